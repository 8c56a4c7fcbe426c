"""Report tier: paper data, Wilson intervals, and the report built from hand-made MCAP logs (no simulator)."""

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from helpers.config import compose_cfg
from helpers.logs import foreign_log

from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.datasets import dataset_objects
from graspexp.record import TrialRecorder
from graspexp.report.agreement import p_below
from graspexp.report.build import build_report, write_report
from graspexp.report.collect import collect
from graspexp.report.paper import BASELINES, SETTINGS, TABLE1, TABLE2
from graspexp.report.render import display_frame, latex_escape
from graspexp.report.stats import wilson_interval
from graspexp.tools.report import main as report_main

# ---------------------------------------------------------------- Wilson interval (hand-computed)


@pytest.mark.parametrize(
    ("k", "n", "lo", "hi"),
    [
        (9, 10, 0.596, 0.982),
        (10, 10, 0.722, 1.0),
        (0, 10, 0.0, 0.278),
        (5, 10, 0.237, 0.763),
        (1, 2, 0.095, 0.905),
    ],
)
def test_wilson_interval_matches_hand_computed_values(k: int, n: int, lo: float, hi: float) -> None:
    got = wilson_interval(k, n)
    assert got == pytest.approx((lo, hi), abs=5e-4)


def test_wilson_interval_edges() -> None:
    assert wilson_interval(0, 10)[0] == 0.0
    assert wilson_interval(10, 10)[1] == 1.0
    assert all(np.isnan(wilson_interval(0, 0)))
    with pytest.raises(ValueError, match="11/10"):
        wilson_interval(11, 10)


# ---------------------------------------------------------------- the paper's numbers as data


@pytest.mark.parametrize("table", [TABLE1, TABLE2])
def test_paper_averages_match_the_printed_rows(table) -> None:
    """The transcription is consistent: the mean of each column rounds to the printed Average."""
    rows = np.array([table.ours[o] for o in table.labels])
    assert rows.shape == (len(table.labels), len(SETTINGS))
    np.testing.assert_allclose(rows.mean(axis=0), table.ours_average, atol=0.006)
    if table.baselines:
        base = np.array([table.baselines[o] for o in table.labels])
        np.testing.assert_allclose(base.mean(axis=0), table.baselines_average, atol=0.006)
    assert len(table.labels) == (9 if table.number == 1 else 13)


def test_paper_tables_use_the_dataset_object_ids() -> None:
    """Row order and ids of paper.py are the datasets' default object lists (paper Table 1 / 2 order)."""
    assert list(TABLE1.labels) == dataset_objects(compose_cfg("dataset=ycb").dataset)
    assert list(TABLE2.labels) == dataset_objects(compose_cfg("dataset=linemod").dataset)


# ---------------------------------------------------------------- a hand-made set of trial logs


def _result(dataset, obj, mode, rot, trial, reason, plan_s) -> dict:
    return TrialResult(
        dataset=dataset,
        object=obj,
        mode=mode,
        rot=rot,
        planner="optimal",
        trial=trial,
        seed=1000 + trial,
        success=reason is None,
        reason=reason,
        error="RuntimeError: boom" if reason == FailureReason.ERROR.value else "",
        timings_s={} if plan_s is None else {"build": 0.1, "settle": 0.2, "plan": plan_s, "execute": 0.3},
    ).to_dict()


# (dataset, object, mode, rot) -> per-trial reasons (None = success); plan time per dataset
CELLS = {
    ("ycb", "021_bleach_cleanser", "collab", "z"): [None] * 9 + ["no_contact"],
    ("ycb", "025_mug", "collab", "z"): [None] * 10,
    ("ycb", "021_bleach_cleanser", "collab", "xyz"): ["dropped"] * 5 + ["slipped"] * 3 + ["error"] * 2,
    ("linemod", "ape", "bin", "z"): [None] * 5 + ["collision_support"] * 5,
}
PLAN_S = {"ycb": 0.05, "linemod": 0.2}


def _write_logs(root: Path) -> None:
    for (dataset, obj, mode, rot), reasons in CELLS.items():
        run_dir = root / f"dataset={dataset},mode={mode},rot={rot}"
        for i, reason in enumerate(reasons):
            plan_s = None if reason == "error" else PLAN_S[dataset]
            with TrialRecorder(run_dir / "trials" / obj / f"{i:03d}.mcap", {"config_yaml": "{}"}) as rec:
                rec.result(0.0, _result(dataset, obj, mode, rot, i, reason, plan_s))


@pytest.fixture(scope="module")
def sweep_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("handmade")
    _write_logs(root)
    return root


def test_collect_reads_every_log(sweep_dir: Path) -> None:
    col = collect(sweep_dir)
    assert len(col.results) + len(col.not_run) == sum(len(v) for v in CELLS.values()) == 40
    assert set(col.not_run["reason"]) == {"error"} and len(col.not_run) == 2  # never scored
    assert col.unreadable == [] and col.duplicates == []


def _cell(table, label: str, mode: str, rot: str) -> pd.Series:
    c = table.cells
    return c[(c["label"] == label) & (c["mode"] == mode) & (c["rot"] == rot)].iloc[0]


def test_table1_exact_percentages_intervals_and_deltas(sweep_dir: Path) -> None:
    report = build_report(sweep_dir)
    assert [t.name for t in report.tables] == ["table1_ycb_optimal", "table2_linemod_optimal"]
    t1 = report.tables[0]
    cleanser = _cell(t1, "Cleanser B.", "collab", "z")
    assert (cleanser["n"], cleanser["successes"], cleanser["ours_pct"]) == (10, 9, 90.0)
    assert (cleanser["lo_pct"], cleanser["hi_pct"]) == pytest.approx((59.6, 98.2), abs=0.05)
    assert cleanser["paper_pct"] == 100.0 and cleanser["delta_pp"] == pytest.approx(-10.0)
    mug = _cell(t1, "Mug", "collab", "z")
    assert (mug["ours_pct"], mug["lo_pct"], mug["hi_pct"]) == pytest.approx((100.0, 72.2, 100.0), abs=0.05)
    assert (cleanser["top_reason"], cleanser["top_reason_n"]) == ("no_contact", 1)
    assert (mug["top_reason"], mug["top_reason_n"]) == ("", 0)
    xyz = _cell(t1, "Cleanser B.", "collab", "xyz")
    assert (xyz["top_reason"], xyz["top_reason_n"]) == ("dropped", 5)
    assert xyz["n"] == 8  # the two trials that ended in an error were not run: no failures of the grasp
    assert (xyz["ours_pct"], xyz["lo_pct"], xyz["hi_pct"], xyz["paper_pct"]) == pytest.approx(
        (0, 0, 32.4, 90), abs=0.05
    )
    # objects without logs stay in the table as n/a, with the paper's value
    meat = _cell(t1, "Meat Can", "collab", "z")
    assert meat["n"] == 0 and np.isnan(meat["ours_pct"]) and meat["paper_pct"] == 90.0
    # Average: mean over the objects we ran (90, 100); paper as printed; paper over the same objects
    avg = _cell(t1, "Average", "collab", "z")
    assert avg["ours_pct"] == pytest.approx(95.0) and avg["paper_pct"] == 92.22
    assert (avg["lo_pct"], avg["hi_pct"]) == pytest.approx(tuple(100 * v for v in wilson_interval(19, 20)))
    assert avg["delta_pp"] == pytest.approx(2.78)
    same = _cell(t1, "Paper avg., same objects", "collab", "z")
    assert same["paper_pct"] == pytest.approx(100.0) and same["delta_pp"] == pytest.approx(-5.0)
    assert _cell(t1, "Paper avg., same objects", "collab", "xyz")["paper_pct"] == pytest.approx(90.0)
    assert np.isnan(_cell(t1, "Average", "bin", "z")["ours_pct"])

    disp = display_frame(t1)
    assert list(disp.index[:9]) == list(TABLE1.labels.values())
    assert disp.loc["Cleanser B.", "Z-Collab ours [95% CI]"] == "90 [59.6, 98.2] no_contact×1"
    assert disp.loc["Cleanser B.", "Z-Collab paper"] == "100"
    assert disp.loc["Cleanser B.", "Z-Collab Δ"] == "-10"
    assert disp.loc["Mug", "Z-Collab ours [95% CI]"] == "100 [72.2, 100]"
    assert disp.loc["Meat Can", "Z-Collab ours [95% CI]"] == "n/a"
    assert disp.loc["Average", "Z-Collab Δ"] == "+2.8"
    assert disp.loc["Average", "Z-Bin paper"] == "94.44"
    assert disp.loc["Mug", "GPD [18]*"] == "30"
    assert disp.loc["Average", "PNGPD 3-cl. [19]*"] == "85.56"


def test_table2_lists_missing_objects_as_na(sweep_dir: Path) -> None:
    t2 = build_report(sweep_dir).tables[1]
    disp = display_frame(t2)
    assert list(disp.index[:13]) == list(TABLE2.labels.values())
    assert disp.loc["Ape", "Z-Bin ours [95% CI]"] == "50 [23.7, 76.3] collision_support×5"
    assert disp.loc["Ape", "Z-Bin Δ"] == "-40"
    assert disp.loc["Bench vise", "Z-Bin ours [95% CI]"] == "n/a"
    assert disp.loc["Bench vise", "Z-Bin paper"] == "90"
    assert not any(c.endswith("*") for c in disp.columns)  # Table 2 has no baseline columns


def test_failure_breakdown_and_runtime(sweep_dir: Path) -> None:
    report = build_report(sweep_dir)
    f = report.failures.set_index(["dataset", "mode", "rot"])
    assert list(f.columns[-len(FailureReason) :]) == [r.value for r in FailureReason]
    row = f.loc[("ycb", "collab", "xyz")]
    assert (row["trials"], row["success"], row["dropped"], row["slipped"], row["error"]) == (10, 0, 5, 3, 2)
    assert row["no_contact"] == 0
    assert f.loc[("ycb", "collab", "z")][["trials", "success", "no_contact"]].tolist() == [20, 19, 1]
    assert f.loc[("linemod", "bin", "z")]["collision_support"] == 5

    rt = report.runtime.set_index("dataset")
    assert rt.loc["ycb", "trials"] == 28  # the two error trials have no plan time
    assert (rt.loc["ycb", "p50_ms"], rt.loc["linemod", "p95_ms"]) == pytest.approx((50.0, 200.0))
    assert (rt.loc["all", "p50_ms"], rt.loc["all", "p95_ms"]) == pytest.approx((50.0, 200.0))
    assert (rt.loc["ycb", "p50_ratio"], rt.loc["linemod", "p50_ratio"]) == pytest.approx((0.5, 2.0))


@pytest.mark.slow
def test_report_cli_writes_markdown_csv_latex_png(sweep_dir: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "rep"
    assert report_main([str(sweep_dir), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "| Cleanser B." in printed and "Unreadable logs (0)" in printed
    for stem in ("table1_ycb_optimal", "table2_linemod_optimal"):
        for ext in ("md", "csv", "tex", "png"):
            assert (out / f"{stem}.{ext}").stat().st_size > 0
        assert (out / f"{stem}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for stem in ("failures", "runtime"):
        for ext in ("md", "csv", "tex"):
            assert (out / f"{stem}.{ext}").is_file()
    for stem in ("agreement_ycb_optimal", "agreement_linemod_optimal"):
        for ext in ("md", "csv", "png"):
            assert (out / f"{stem}.{ext}").stat().st_size > 0
    assert "## Agreement with the paper: ycb, planner optimal" in printed
    assert "Z-Collab in area" in printed and "held, contacts in area %" in printed
    flagged = pd.read_csv(out / "agreement_ycb_optimal.csv").query("flagged")
    assert list(flagged["label"]) == ["Cleanser B.", "All objects (pooled)"]
    assert (
        out / "agreement"
    ).is_dir() and "agreement/ycb_optimal_collab_xyz_021_bleach_cleanser_000.png" in printed
    assert (out / "report.md").read_text() in printed
    csv = pd.read_csv(out / "table1_ycb_optimal.csv", index_col="label")
    assert csv.loc["Cleanser B.", "collab_z_ours_pct"] == 90.0
    assert csv.loc["Cleanser B.", "collab_z_lo_pct"] == pytest.approx(59.6, abs=0.05)
    assert csv.loc["Cleanser B.", "GPD [18] (paper)"] == 100
    assert np.isnan(csv.loc["Meat Can", "collab_z_ours_pct"])
    tex = (out / "table1_ycb_optimal.tex").read_text()
    assert r"\begin{tabular}" in tex and "Cleanser B." in tex and r"[95\% CI]" in tex and r"$\Delta$" in tex
    assert latex_escape("a_b & 5%") == r"a\_b \& 5\%"
    assert set(BASELINES) <= set(csv.columns.str.replace(" (paper)", ""))


def test_report_cli_on_a_dir_without_logs_is_an_error(tmp_path: Path, capsys) -> None:
    assert report_main([str(tmp_path)]) == 2
    assert "no trial logs" in capsys.readouterr().err


@pytest.mark.slow
def test_corrupt_and_unfinished_logs_are_named_not_dropped(sweep_dir: Path, tmp_path: Path, capsys) -> None:
    import shutil

    root = tmp_path / "sweep"
    shutil.copytree(sweep_dir, root)
    run = root / "dataset=ycb,mode=collab,rot=z" / "trials" / "025_mug"
    good = (run / "000.mcap").read_bytes()
    (run / "010.mcap").write_bytes(good[: len(good) // 2])  # truncated
    (run / "011.mcap").write_bytes(b"not an mcap file at all")  # garbage
    (run / "012.mcap.partial").write_bytes(good[:100])  # writer killed mid-trial
    assert report_main([str(root)]) == 1  # written, but not every log was read
    text = capsys.readouterr().out
    section = text[text.index("## Unreadable logs (3)") :]
    for name in ("010.mcap", "011.mcap", "012.mcap.partial"):
        assert str(run / name) in section
    assert "truncated" in section and "bad magic" in section and "unfinished" in section
    unreadable = pd.read_csv(root / "report" / "unreadable.csv")
    assert sorted(Path(p).name for p in unreadable["path"]) == ["010.mcap", "011.mcap", "012.mcap.partial"]
    # the readable logs are still counted exactly as before
    t1 = build_report(root).tables[0]
    assert _cell(t1, "Mug", "collab", "z")["n"] == 10


@pytest.mark.parametrize(
    "meta, change, reason",
    [
        (None, {}, "not a graspexp trial log (no graspexp metadata)"),  # a foreign MCAP with a /result
        ({"config_yaml": "{}"}, {"success": "false"}, "success='false' is not"),
        ({"config_yaml": "{}"}, {"trial": "abc"}, "trial='abc' is not"),
        ({"config_yaml": "- 1"}, {}, "its recorded config is not a job config"),
    ],
)
def test_foreign_or_forged_logs_are_unreadable_not_counted(sweep_dir, tmp_path, meta, change, reason) -> None:
    import shutil

    root = tmp_path / "sweep"
    shutil.copytree(sweep_dir / "dataset=ycb,mode=collab,rot=z", root)
    result = {**_result("ycb", "025_mug", "collab", "z", 10, None, 0.05), **change}
    path = root / "trials" / "025_mug" / "010.mcap"
    if meta is None:
        foreign_log(path, result)
    else:
        with TrialRecorder(path, meta) as rec:
            rec.result(0.0, result)
    col = collect(root)
    assert len(col.results) == 20 and [(p.name, r) for p, r in col.unreadable if reason in r] == [
        ("010.mcap", col.unreadable[0][1])
    ]


def test_a_cell_with_two_configs_is_refused_in_one_line(tmp_path: Path, capsys) -> None:
    for i, gripper in enumerate(("rg2", "panda")):
        meta = {"config_yaml": f"gripper: {{name: {gripper}}}\ntrials: {i + 1}\n"}
        with TrialRecorder(tmp_path / f"run{i}" / "trials" / "025_mug" / f"{i:03d}.mcap", meta) as rec:
            rec.result(0.0, _result("ycb", "025_mug", "collab", "z", i, None, 0.05))
    assert report_main([str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("graspexp report: error: ycb/optimal/collab/z/0.0/0.0 holds trials of two configs")
    assert "differing keys: gripper.name;" in err and "\n" not in err


def test_duplicate_trials_are_counted_once_and_named(sweep_dir: Path, tmp_path: Path) -> None:
    import shutil

    root = tmp_path / "twice"
    shutil.copytree(sweep_dir / "dataset=linemod,mode=bin,rot=z", root / "a")
    shutil.copytree(sweep_dir / "dataset=linemod,mode=bin,rot=z", root / "b")
    col = collect(root)
    assert len(col.results) == 10 and len(col.duplicates) == 10
    text = write_report(build_report(root), tmp_path / "out")
    assert "## Duplicate trials (10)" in text


# ---------------------------------------------------------------- agreement with the paper


@pytest.mark.parametrize(
    ("ours", "paper", "p"),
    [
        ((0, 10), (10, 10), 1 / 184756),  # 1 / C(20, 10)
        ((6, 10), (10, 10), 210 / 4845),  # C(10, 6) / C(20, 16)
        ((7, 10), (10, 10), 120 / 1140),
        ((10, 10), (10, 10), 1.0),
        ((10, 30), (10, 10), None),  # checked against scipy below
    ],
)
def test_fisher_one_sided_p_below_the_paper(ours, paper, p) -> None:
    from scipy.stats import fisher_exact

    got = p_below(*ours, *paper)
    expected = p if p is not None else fisher_exact([[10, 20], [10, 0]], alternative="less").pvalue
    assert got == pytest.approx(expected, rel=1e-9)
    assert p_below(0, 0, 5) == 1.0


def test_agreement_flags_cells_below_the_paper_with_their_failure_reason(sweep_dir: Path) -> None:
    report = build_report(sweep_dir, progress=False)
    ag = {a.dataset: a for a in report.agreements}
    assert set(ag) == {"ycb", "linemod"}
    cells = ag["ycb"].objects.set_index(["label", "mode", "rot"])
    bleach_z = cells.loc[("Cleanser B.", "collab", "z")]
    assert (bleach_z["ours_k"], bleach_z["ours_n"], bleach_z["paper_k"]) == (9, 10, 10)
    assert bleach_z["p_below"] == pytest.approx(0.5) and not bleach_z["flagged"]
    bleach_xyz = cells.loc[("Cleanser B.", "collab", "xyz")]  # 0/8 run (2 not run) against the paper's 9/10
    assert bleach_xyz["flagged"] and bleach_xyz["top_reason"] == "dropped"
    assert bleach_xyz["p_below"] == pytest.approx(p_below(0, 8, 9))
    ape = ag["linemod"].objects.set_index("label").loc["Ape"]  # 5/10 against 9/10: p = 0.07
    assert ape["p_below"] == pytest.approx(p_below(5, 10, 9)) and not ape["flagged"]
    # One pooled row per setting: every trial of the paper objects we ran against their printed rates.
    pooled = ag["ycb"].cells[ag["ycb"].cells["object"] == ""].set_index(["mode", "rot"])
    assert (pooled.loc[("collab", "z"), "ours_k"], pooled.loc[("collab", "z"), "ours_n"]) == (19, 20)
    assert (pooled.loc[("collab", "z"), "paper_k"], pooled.loc[("collab", "z"), "paper_n"]) == (20, 20)
    summary = ag["ycb"].summary()
    assert summary.startswith("ycb / optimal: 1 of 3 object cells significantly below the paper")
    assert "settings significantly below: XYZ Collaborative" in summary


def test_in_area_criterion_is_na_where_it_cannot_be_told_and_zero_without_contacts(sweep_dir: Path) -> None:
    """The hand-made logs hold no contacts: a held trial without contacts is not held in the area."""
    report = build_report(sweep_dir, progress=False)
    mug = _cell(report.tables[0], "Mug", "collab", "z")
    assert mug["ours_pct"] == 100.0 and mug["in_area_pct"] == 0.0
    assert set(report.strict["in_area_pct"]) == {0.0}
    disp = display_frame(report.tables[0])
    assert disp.loc["Mug", "Z-Collab in area"] == "0"


def test_compare_runs_matches_a_renamed_preset_cell_by_cell(tmp_path: Path, capsys) -> None:
    from graspexp.tools.bench.compare_runs import main as compare_main

    rows = "dataset,object,planner,trial,success,timings_s\nycb,mug,{p},0,True,{{'plan': {t}}}\n"
    for name, planner, t in (("before", "optimal", 0.1), ("after", "optimal_in_area", 0.2)):
        job = tmp_path / name / f"dataset=ycb,mode=bin,planner={planner},rot=z"
        job.mkdir(parents=True)
        (job / "results.csv").write_text(rows.format(p=planner, t=t))
    before, after = str(tmp_path / "before"), str(tmp_path / "after")
    assert compare_main([before, after]) == 1  # other job directory names
    assert compare_main([before, after, "--planner", "optimal=optimal_in_area"]) == 0
    assert "1 rows: identical" in capsys.readouterr().out
    (tmp_path / "after" / "dataset=ycb,mode=bin,planner=optimal_in_area,rot=z" / "results.csv").write_text(
        rows.format(p="optimal_in_area", t=0.2).replace("True", "False")
    )
    assert compare_main([before, after, "--planner", "optimal=optimal_in_area"]) == 1
    assert "success: 'True' != 'False'" in capsys.readouterr().out


def test_collect_reads_results_csv_only_where_a_run_has_no_logs(sweep_dir: Path, tmp_path: Path) -> None:
    """The one results reader: logs first; a run without logs (``record=false``) by its results.csv,
    with its noise level from the run's .hydra/config.yaml; never both for one run."""
    import shutil

    root = tmp_path / "mixed"
    shutil.copytree(sweep_dir, root / "logged")
    logged = collect(root / "logged").results
    # a logged run's results.csv is a cache: not read again
    run = next((root / "logged").glob("dataset=ycb,mode=collab,rot=z"))
    logged[logged["path"].str.contains("mode=collab,rot=z")].drop(columns=["path"]).to_csv(
        run / "results.csv", index=False
    )
    # a run without logs: its results.csv, noise from .hydra/config.yaml
    unlogged = root / "unlogged"
    (unlogged / ".hydra").mkdir(parents=True)
    (unlogged / ".hydra" / "config.yaml").write_text(
        "perception:\n  noise:\n    trans_mm: 10\n    rot_deg: 0\n"
    )
    pd.DataFrame(
        [
            {
                "dataset": "ycb",
                "planner": "optimal",
                "mode": "bin",
                "rot": "z",
                "object": "025_mug",
                "trial": t,
                "seed": t,
            }
            | {"success": t % 2 == 0, "reason": "" if t % 2 == 0 else "dropped", "timings_s": "{'plan': 0.5}"}
            for t in range(4)
        ]
    ).to_csv(unlogged / "results.csv", index=False)
    col = collect(root)
    assert col.duplicates == [] and len(col.results) == len(logged) + 4
    rows = col.results[col.results["path"] == ""]
    assert list(rows["success"]) == [True, False, True, False]
    assert set(rows["trans_mm"]) == {10.0} and set(rows["plan_ms"]) == {500.0}
    assert set(col.results.loc[col.results["path"] != "", "trans_mm"]) == {0.0}


@pytest.mark.parametrize(
    "field, value, match",
    [
        ("success", "yes", r"row 3: success='yes' is not <class 'bool'>"),
        ("trial", str(10**30), r"row 3: trial='1000000000000000000000000000000' is not <class 'int'>"),
        ("reason", "exploded", r"row 3: result field reason='exploded' is not a failure reason"),
        ("timings_s", "*a", r"row 3: timings_s='\*a' is not"),
    ],
)
def test_a_bad_results_csv_is_unreadable_in_one_line_never_a_traceback(tmp_path, field, value, match):
    rows = [
        {"dataset": "ycb", "object": "025_mug", "mode": "bin", "rot": "z", "planner": "optimal", "trial": t,
         "seed": t, "success": False, "reason": "dropped", "timings_s": "{'plan': 0.5}"}
        for t in range(2)
    ]  # fmt: skip
    rows[1][field] = value
    pd.DataFrame(rows).to_csv(tmp_path / "results.csv", index=False)
    col = collect(tmp_path)
    assert col.results.empty and len(col.unreadable) == 1
    ((path, why),) = col.unreadable
    assert path == tmp_path / "results.csv" and re.search(match, why) and "\n" not in why


@pytest.mark.parametrize(
    "metas, mode, match",
    [  # one cache key, two shapes (a rewritten shared cache entry), in two settings of one report
        ([{"collision_key": "k", "collision_sha256": s} for s in ("a" * 64, "b" * 64)], ("z", "xyz"), "two collision shapes"),
        ([{"area_sha256": s} for s in ("a" * 64, "b" * 64)], ("z", "z"), "two grasping areas"),
    ],
)  # fmt: skip
def test_a_report_never_merges_two_collision_shapes_or_areas(tmp_path, capsys, metas, mode, match) -> None:
    for i, (meta, rot) in enumerate(zip(metas, mode, strict=True)):
        path = tmp_path / f"run{i}" / "trials" / "025_mug" / f"{i:03d}.mcap"
        with TrialRecorder(path, {"config_yaml": "{}", **meta}) as rec:
            rec.result(0.0, _result("ycb", "025_mug", "collab", rot, i, None, 0.05))
    assert report_main([str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"graspexp report: error: trials of 025_mug used {match}") and "\n" not in err


def test_a_trial_that_never_came_to_rest_is_its_own_failure_class(tmp_path: Path) -> None:
    """Logs from before ``not_at_rest`` existed planned on the moving object and may say success: the
    report counts them as ``not_at_rest``, never as a success or a grasp failure."""
    for i, reason in enumerate((None, "no_contact", None)):
        result = _result("ycb", "025_mug", "collab", "z", i, reason, 0.05) | {"at_rest": i == 2}
        with TrialRecorder(
            tmp_path / "run" / "trials" / "025_mug" / f"{i:03d}.mcap", {"config_yaml": "{}"}
        ) as rec:
            rec.result(0.0, result)
    report = build_report(tmp_path)
    row = report.failures.set_index(["dataset", "mode", "rot"]).loc[("ycb", "collab", "z")]
    assert (row["trials"], row["success"], row["not_at_rest"], row["no_contact"]) == (3, 1, 2, 0)


def test_an_object_that_never_ran_is_na_in_the_paper_table_not_zero(tmp_path: Path) -> None:
    """An unreadable ape (every trial ``error``) once read as 0 % with a delta of -45 and pulled the Average
    down; it is n/a, out of the Average, and listed as not run."""
    for obj, reason in (("ape", "error"), ("cat", None)):
        for i in range(2):
            path = tmp_path / "run" / "trials" / obj / f"{i:03d}.mcap"
            with TrialRecorder(path, {"config_yaml": "{}"}) as rec:
                rec.result(0.0, _result("linemod", obj, "collab", "z", i, reason, 0.05))
    report = build_report(tmp_path)
    ape, avg = (
        _cell(report.tables[0], "Ape", "collab", "z"),
        _cell(report.tables[0], "Average", "collab", "z"),
    )
    assert ape["n"] == 0 and np.isnan(ape["ours_pct"]) and avg["ours_pct"] == 100.0
    text = write_report(report, tmp_path / "out", gallery_per_reason=0)
    assert "## Not run (2 trials)" in text and "linemod/optimal/collab/z 'ape': 2 trial(s) not run" in text


def test_held_out_objects_of_a_paper_dataset_average_over_themselves() -> None:
    """A run of YCB objects the paper does not list (``dataset.split=test``): the Average is over the
    objects run, beside the paper's printed Average for scale; with a paper object among them, over the
    paper's objects only (the paper's own Average)."""
    from graspexp.report.tables import AVERAGE, success_table

    def rows(objects):
        return pd.DataFrame(
            [{"dataset": "ycb", "planner": "optimal_plus", "object": o, "mode": "collab", "rot": "z",
              "success": s, "reason": None if s else "dropped"}
             for o, outcomes in objects.items() for s in outcomes]
        )  # fmt: skip

    held_out = {"003_cracker_box": [True, True], "024_bowl": [True, False]}

    def average(objects):
        cells = success_table(rows(objects), "ycb", "optimal_plus").cells
        return cells[cells["label"] == AVERAGE].iloc[0]

    avg = average(held_out)
    assert avg["n"] == 4 and avg["ours_pct"] == pytest.approx(75.0) and np.isfinite(avg["paper_pct"])
    mixed = {**held_out, "025_mug": [True, False]}
    avg = average(mixed)
    assert avg["n"] == 2 and avg["ours_pct"] == pytest.approx(50.0)  # the paper's objects only
