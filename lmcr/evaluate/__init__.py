"""The paper's evaluation protocol (section IV) on crowd-rated frames, and its reports."""
