"""The settings of an MTurk HIT batch a requester publishes: title, reward, timing, assignments and
worker qualifications. Light on purpose (the CLI reads its defaults at start-up)."""

from __future__ import annotations

import re
from dataclasses import dataclass

from lmcr.errors import LMCRError

# MTurk's system qualification types (the requester API's QualificationTypeId values).
APPROVAL_RATE_QUALIFICATION = "000000000000000000L0"
APPROVED_HITS_QUALIFICATION = "00000000000000000040"
LOCALE_QUALIFICATION = "00000000000000000071"


class HitSettingsError(LMCRError, ValueError):
    """HIT settings MTurk would refuse (a reward, duration, qualification or locale out of range)."""


@dataclass(frozen=True)
class HitSettings:
    """What a requester sets when publishing the batch; written to tasks.json in the requester API's
    CreateHITType / CreateHITWithHITType field names, so the batch can be published as it is."""

    title: str = "Rate how sensible a kitchen action is"
    description: str = "Read short sentences about kitchen actions and rate each from 1 to 5."
    keywords: str = "rating, common sense, cooking"
    reward: str = "0.30"  # US dollars per assignment
    assignment_duration_s: int = 1800
    lifetime_s: int = 7 * 24 * 3600
    auto_approval_delay_s: int = 3 * 24 * 3600
    assignments: int = 3  # workers per HIT
    min_approval_rate: int = 95  # percent of the worker's past assignments approved; 0: no requirement
    min_approved_hits: int = 100  # 0: no requirement
    locale: str = "US"  # worker country (ISO 3166 code); "": any

    def __post_init__(self) -> None:
        if not re.fullmatch(r"\d{1,3}\.\d{2}", self.reward) or float(self.reward) <= 0:
            raise HitSettingsError(f"reward must be dollars and cents such as 0.30, not {self.reward!r}")
        positive = {
            "assignment duration": self.assignment_duration_s,
            "lifetime": self.lifetime_s,
            "assignments": self.assignments,
        }
        for name, value in positive.items():
            if value < 1:
                raise HitSettingsError(f"{name} must be at least 1, not {value}")
        if not 0 <= self.min_approval_rate <= 100:
            raise HitSettingsError(f"approval rate is a percentage, not {self.min_approval_rate}")
        if self.min_approved_hits < 0:
            raise HitSettingsError(f"approved HITs cannot be negative ({self.min_approved_hits})")
        if self.locale and not re.fullmatch(r"[A-Z]{2}", self.locale):
            raise HitSettingsError(f"locale must be a two-letter country code such as US, not {self.locale!r}")

    def qualifications(self) -> list[dict]:
        found = []
        if self.min_approval_rate:
            found.append(
                {
                    "QualificationTypeId": APPROVAL_RATE_QUALIFICATION,
                    "Comparator": "GreaterThanOrEqualTo",
                    "IntegerValues": [self.min_approval_rate],
                }
            )
        if self.min_approved_hits:
            found.append(
                {
                    "QualificationTypeId": APPROVED_HITS_QUALIFICATION,
                    "Comparator": "GreaterThanOrEqualTo",
                    "IntegerValues": [self.min_approved_hits],
                }
            )
        if self.locale:
            found.append(
                {
                    "QualificationTypeId": LOCALE_QUALIFICATION,
                    "Comparator": "EqualTo",
                    "LocaleValues": [{"Country": self.locale}],
                }
            )
        return found

    def to_json(self) -> dict:
        return {
            "Title": self.title,
            "Description": self.description,
            "Keywords": self.keywords,
            "Reward": self.reward,
            "AssignmentDurationInSeconds": self.assignment_duration_s,
            "LifetimeInSeconds": self.lifetime_s,
            "AutoApprovalDelayInSeconds": self.auto_approval_delay_s,
            "MaxAssignments": self.assignments,
            "QualificationRequirements": self.qualifications(),
        }
