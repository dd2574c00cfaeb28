"""The evaluation protocol: lambda split, scenario builder (seeds, skips), tie rule, accuracy, report."""

from __future__ import annotations

import json

import pytest

from lmcr.evaluate.protocol import EvalConfig, Results, evaluate
from lmcr.evaluate.ratings import RatedFrame
from lmcr.evaluate.report import table1_markdown, write_report
from lmcr.evaluate.scenarios import accuracy, build_scenarios, label, scenario_credit

OBJECTS = ["cup", "glass", "mug", "bowl", "scissors", "knife", "towel", "sponge", "oven", "sink", "plate", "spoon"]


def rated(verbs=("pour", "fill")) -> list[RatedFrame]:
    """Per verb: water into the first four objects is plausible (4.7), the rest implausible (1.3)."""
    return [
        RatedFrame(v, "Theme", "water", "Destination", o, 4.7 if i < 4 else 1.3, 3)
        for v in verbs
        for i, o in enumerate(OBJECTS)
    ]


@pytest.mark.parametrize(
    "mean,lam,expected",
    [
        (4.2, 1.0, {"positive"}),
        (1.9, 1.0, {"negative"}),
        (3.0, 1.0, set()),
        (4.0, 1.0, set()),
        (3.5, 1.6, {"positive"}),
    ],
)
def test_lambda_split(mean, lam, expected):
    assert label(mean, lam) == expected


@pytest.mark.parametrize("scores,credit", [([1, 0, 0], 1.0), ([1, 1, 0], 0.5), ([1, 1, 1], 1 / 3), ([0, 1, 0], 0.0)])
def test_tie_rule(scores, credit):
    assert scenario_credit(scores) == pytest.approx(credit)


def test_scenarios_are_seeded_and_shaped():
    frames = rated()
    a, skipped = build_scenarios(frames, 1.0, 6, per_verb=10, seed=3)
    b, _ = build_scenarios(frames, 1.0, 6, per_verb=10, seed=3)
    c, _ = build_scenarios(frames, 1.0, 6, per_verb=10, seed=4)
    assert a == b and a != c and not skipped
    assert len(a) == 20
    for sc in a:
        assert sc.positive.mean > 4 and len(sc.negatives) == 5 and all(n.mean < 2 for n in sc.negatives)
        assert len(set(sc.candidates)) == 6 and sc.fixed_value == "water"


def test_a_verb_without_enough_negatives_is_skipped_with_a_reason():
    scenarios, skipped = build_scenarios(rated(), 1.0, 10, per_verb=5)  # 8 negatives < 9
    assert scenarios == [] and set(skipped) == {"fill", "pour"} and "9 negatives" in skipped["pour"]


def test_accuracy_of_an_oracle_a_constant_and_a_half_right_method():
    frames = rated()
    scenarios, _ = build_scenarios(frames, 1.0, 6, per_verb=20)
    oracle = {f.key: f.mean for f in frames}
    constant = {f.key: 0.0 for f in frames}
    half = {f.key: (f.mean if f.verb == "pour" else -f.mean) for f in frames}
    assert accuracy(scenarios, oracle) == {"all": 1.0, "fill": 1.0, "pour": 1.0}
    assert accuracy(scenarios, constant)["all"] == pytest.approx(1 / 6)
    assert accuracy(scenarios, half) == {"all": 0.5, "fill": 0.0, "pour": 1.0}


def test_sweeps_skip_infeasible_k_and_the_report_is_complete(tmp_path):
    frames = rated()
    scores = {"oracle": {f.key: f.mean for f in frames}, "reverse": {f.key: -f.mean for f in frames}}
    results = evaluate(frames, scores, EvalConfig(per_verb=5, min_verbs=1))
    assert results.table1["oracle"]["all"] == 1.0 and results.table1["reverse"]["all"] == 0.0
    assert set(results.vs_k["oracle"]) == {4, 6} and {10, 20, 30, 40} <= set(results.skipped_k)
    assert results.vs_lambda["oracle"][1.0] == 1.0
    out = write_report(results, ["oracle", "reverse"], [], tmp_path / "report", ["a note"])
    names = {p.name for p in out.iterdir()}
    assert {"report.md", "report.html", "figures.json", "fig4a.png", "fig4b.png", "fig4c.png", "fig4d.png"} <= names
    assert "| all | 1.000 | 0.000 |" in (out / "report.md").read_text()
    assert (out / "report.html").read_text().count("data:image/png;base64,") == 4
    assert json.loads((out / "figures.json").read_text())["fig4a"]["oracle"]["1"] == 1.0
    write_report(results, ["oracle"], [], out, [])  # re-run replaces the folder whole
    assert "reverse" not in (out / "report.md").read_text()


def test_paper_columns_only_for_the_papers_methods():
    results = Results(EvalConfig())
    results.table1 = {m: {"pour": 1.0, "all": 1.0} for m in ("sentence_lm", "frame_counts", "sentence_lm+frame_counts")}
    paper = {"sentence_lm": {"pour": 0.6, "all": 0.7}, "random": {"all": 0.15}}
    head, rule, *rows = table1_markdown(results, list(results.table1), paper).splitlines()
    assert head.endswith("| paper sentence_lm |") and "paper frame_counts" not in head and "paper random" not in head
    assert rule.count("---") == 5 and rows[-1] == "| all | 1.000 | 1.000 | 1.000 | 0.700 |"
    assert "paper" not in table1_markdown(results, list(results.table1), {}).splitlines()[0]


def test_paper_table_read_from_latex(tmp_path):
    from lmcr.evaluate.paper import PaperTableError, read_paper_table

    tex = tmp_path / "paper.tex"
    tex.write_text(r"""\begin{table}\caption{x}\label{tab:res}
\begin{tabularx}{\linewidth}{l YYYYY}
\toprule
{} & \textbf{Random} & & \textbf{Word2Vec} & \multicolumn{2}{r}{\textbf{LMCR (Ours)}} \\
{} & & \textbf{Cooccur} & & \multicolumn{1}{X}{\textbf{ConceptNet}} & \\
\midrule
pour & 0.08 & \textbf{0.74} & 0.56 & 0.52 & 0.60 \\
\midrule
Overall & 0.15 & 0.62 & 0.48 & 0.52 & \textbf{0.70} \\
\bottomrule
\end{tabularx}
\end{table}""")
    table = read_paper_table(tex)
    assert table["cooccur"] == {"pour": 0.74, "all": 0.62} and table["conceptnet"]["pour"] == 0.52
    assert table["sentence_lm"] == {"pour": 0.60, "all": 0.70} and table["random"]["all"] == 0.15
    tex.write_text(r"\begin{table}\label{tab:other}\end{table}")
    with pytest.raises(PaperTableError, match="no table labelled tab:res"):
        read_paper_table(tex)


@pytest.mark.shared
def test_the_papers_own_table(shared_dir):
    from lmcr.evaluate.paper import read_paper_table

    table = read_paper_table(shared_dir / "paper" / "lmcr_icra2020.tex")
    assert set(table) == {"random", "cooccur", "word2vec", "conceptnet", "sentence_lm"}
    assert all(len(verbs) == 12 for verbs in table.values())  # 11 verbs and Overall
    assert table["sentence_lm"]["all"] == 0.70 and table["cooccur"]["fry"] == 0.86
