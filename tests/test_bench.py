"""Tests of the speed/accuracy and stability study (pipeline.study, run as ``bench study``)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pipeline.study import analysis, grids
from pipeline.study.analysis import breakdown_point, pareto_front

# ---------------------------------------------------------------------------------------------
# Pareto front


def test_pareto_front_known_answer():
    t = [1.0, 2.0, 3.0, 2.5, 4.0, 1.0]
    e = [5.0, 1.0, 0.5, 2.0, 0.5, 6.0]
    # (2.5, 2.0) is beaten by (2.0, 1.0); (4.0, 0.5) by (3.0, 0.5); (1.0, 6.0) by (1.0, 5.0)
    assert pareto_front(t, e).tolist() == [True, True, True, False, False, False]


def test_pareto_front_ties_and_nan():
    # identical points do not dominate each other; NaN points are never on the front
    assert pareto_front([1.0, 1.0, np.nan, 0.5], [2.0, 2.0, 0.1, np.nan]).tolist() == [
        True,
        True,
        False,
        False,
    ]
    assert pareto_front([], []).tolist() == []
    with pytest.raises(ValueError):
        pareto_front([1.0, 2.0], [1.0])


def test_pareto_front_single_best_point_dominates_all():
    rng = np.random.default_rng(3)
    t = rng.uniform(1, 10, 50)
    e = rng.uniform(1, 10, 50)
    t[17], e[17] = 0.5, 0.5
    assert np.flatnonzero(pareto_front(t, e)).tolist() == [17]


# ---------------------------------------------------------------------------------------------
# breakdown point


def test_breakdown_point_ascending_sweep():
    assert breakdown_point(
        [0, 1, 2, 4, 8], [0.2, 0.4, 1.0, 3.0, 9.0], [0, 0, 0, 0, 0], nominal=0
    ) == (4.0, "p95 > 2 deg")


def test_breakdown_point_failure_counts_even_if_accurate():
    assert breakdown_point(
        [100, 80, 60, 40], [0.1, 0.1, 0.1, 0.1], [0, 0, 0.05, 0], nominal=100
    ) == (60.0, "failure")


def test_breakdown_point_outward_from_nominal_both_sides():
    values = [-360, -180, -3, 0, 3, 180, 360]
    p95 = [9.0, 5.0, 0.1, 0.1, 0.1, 0.3, 7.0]
    # scanned 0, -3, 3, -180, 180, ...: -180 is the first bad one
    assert breakdown_point(values, p95, np.zeros(7), nominal=0) == (-180.0, "p95 > 2 deg")
    # order of the inputs does not matter
    assert breakdown_point(values[::-1], p95[::-1], np.zeros(7), nominal=0)[0] == -180.0


def test_breakdown_point_none_and_nan():
    v, reason = breakdown_point([0, 1, 2], [0.1, 0.2, 2.0], [0, 0, 0], nominal=0)
    assert np.isnan(v) and reason == ""  # exactly 2 deg is not above the threshold
    # no angle at all (p95 NaN) breaks it
    assert breakdown_point([0, 1, 2], [0.1, np.nan, 0.1], [0, 0, 0], nominal=0)[0] == 1.0
    assert breakdown_point([0, 1], [0.5, 0.9], [0, 0], nominal=0, threshold_deg=0.6)[0] == 1.0


# ---------------------------------------------------------------------------------------------
# tables on crafted per-image results


def _results(rows: list[dict]) -> pd.DataFrame:
    base = {
        "kind": "sweep",
        "nominal": 0.0,
        "bulge": 0.0,
        "seed": 0,
        "status": "ok",
        "degree": np.nan,
        "seconds": 0.01,
        "decode_seconds": 0.002,
    }
    df = pd.DataFrame([{**base, **r} for r in rows])
    df["abs_error_deg"] = (df["psi_deg"] - df["psi_true_deg"]).abs()
    return df


def test_speed_accuracy_stats_exclude_failures_and_mark_pareto():
    rows = []
    for i, err in enumerate([0.1, 0.2, 0.3, 0.4]):
        rows.append({"case_id": i, "condition": "psi", "value": 10.0 * i, "psi_true_deg": 10.0 * i,
                     "method": "fast", "psi_deg": 10.0 * i + err, "seconds": 0.001})
        rows.append({"case_id": i, "condition": "psi", "value": 10.0 * i, "psi_true_deg": 10.0 * i,
                     "method": "slow", "psi_deg": 10.0 * i + 2 * err, "seconds": 0.010})
    rows.append(
        {
            "case_id": 9,
            "condition": "psi",
            "value": 90.0,
            "psi_true_deg": 90.0,
            "method": "fast",
            "psi_deg": np.nan,
            "status": "failed",
            "seconds": 0.001,
        }
    )
    rows.append(
        {
            "case_id": 9,
            "condition": "psi",
            "value": 90.0,
            "psi_true_deg": 90.0,
            "method": "slow",
            "psi_deg": 90.0 + 7.0,
            "seconds": 0.010,
        }
    )
    sa = analysis.speed_accuracy(_results(rows)).set_index(["condition", "method"])
    fast, slow = sa.loc[("nominal", "fast")], sa.loc[("nominal", "slow")]
    assert fast["n"] == 5 and fast["failure_rate"] == pytest.approx(0.2)
    assert fast["median_abs_error_deg"] == pytest.approx(0.25)
    assert fast["p95_abs_error_deg"] == pytest.approx(np.percentile([0.1, 0.2, 0.3, 0.4], 95))
    assert slow["silent_wrong_rate"] == pytest.approx(0.2)  # the 7 deg "ok" row
    assert slow["median_abs_error_deg"] == pytest.approx(0.6)
    assert fast["median_ms_per_image"] == pytest.approx(1.0)
    assert bool(fast["pareto"]) and not bool(slow["pareto"])


def test_stability_breakdown_and_repeatability_tables():
    rows = []
    for i, noise in enumerate([0.0, 1.0, 2.0, 4.0]):
        for rep in range(3):
            err = [0.1, 0.5, 3.0, 8.0][i]
            rows.append(
                {
                    "case_id": 10 * i + rep,
                    "condition": "noise",
                    "value": noise,
                    "nominal": 1.0,
                    "psi_true_deg": 60.0,
                    "method": "m",
                    "psi_deg": 60.0 + err,
                }
            )
    for k, psi in enumerate([119.0, 121.0, 120.0, 120.0]):
        rows.append({"case_id": 100 + k, "kind": "repeat", "condition": "repeat", "value": 120.0,
                     "psi_true_deg": 120.0, "method": "m", "psi_deg": psi})
    res = _results(rows)
    stab = analysis.stability(res)
    assert stab["value"].tolist() == [0.0, 1.0, 2.0, 4.0]
    assert stab["p95_abs_error_deg"].tolist() == pytest.approx([0.1, 0.5, 3.0, 8.0])
    bd = analysis.breakdown(stab).iloc[0]
    assert bd["breakdown_value"] == 2.0 and bd["last_good_value"] == 1.0
    assert bd["bad_values"] == "2;4" and bd["n_bad_values"] == 2
    rep = analysis.repeatability(res).iloc[0]
    assert rep["n_seeds"] == 4 and rep["bias_deg"] == pytest.approx(0.0)
    assert rep["sd_deg"] == pytest.approx(np.std([119, 121, 120, 120], ddof=1))
    assert rep["robust_sd_deg"] == pytest.approx(1.4826 * 0.5)  # median of |x - 120| = (1, 1, 0, 0)


def test_model_choice_consistency():
    rows = []
    for i, (bulge, deg) in enumerate([(0.0, 1), (0.0, 1), (0.0, 3), (0.5, 3), (0.5, 4), (0.5, 1)]):
        rows.append(
            {
                "case_id": i,
                "condition": "bulge",
                "value": bulge,
                "bulge": bulge,
                "psi_true_deg": 90.0,
                "method": "turning",
                "psi_deg": 90.0,
                "degree": deg,
            }
        )
    choice = analysis.model_choice(_results(rows))
    flat = choice.set_index("bulge")
    assert flat.loc[0.0, "share_richer"] == pytest.approx(1 / 3)
    assert flat.loc[0.0, "consistent"] == pytest.approx(2 / 3)
    assert flat.loc[0.5, "consistent"] == pytest.approx(2 / 3)
    assert flat.loc[0.0, "degree_counts"] == "1:2;3:1"
    s = analysis.model_choice_summary(choice).iloc[0]
    assert (
        s["method"] == "turning"
        and s["richer_on_constant"] == pytest.approx(1 / 3)
        and s["richer_on_bulged"] == pytest.approx(2 / 3)
    )


# ---------------------------------------------------------------------------------------------
# grids


def test_grids_cover_the_issue_conditions():
    for name, grid in grids.GRIDS.items():
        names = {s.name for s in grid.sweeps}
        assert {
            "psi",
            "noise",
            "blur",
            "jpeg",
            "contrast",
            "resolution",
            "width",
            "occlusion",
            "clutter",
            "tilt",
            "bulge",
        } <= names, name
        for s in grid.sweeps:
            assert s.nominal in s.values, (name, s.name)
        psi = next(s for s in grid.sweeps if s.name == "psi").values
        assert min(psi) == -360 and max(psi) == 360
        assert {-1.0, 0.0, 1.0, -180.0, 180.0, 170.0, 190.0} <= set(psi)
        assert grid.repeat_seeds == 20
        c = grids.cases(grid)
        assert [x.case_id for x in c] == list(range(len(c)))
        assert c == grids.cases(grid)  # deterministic
        rep = [x for x in c if x.kind == "repeat"]
        assert len(rep) == 20 * len(grid.repeat_psis_deg)
        for psi in grid.repeat_psis_deg:  # 20 distinct noise seeds per repeated scene
            assert len({x.seed for x in rep if x.psi_deg == psi}) == 20
    assert len(grids.cases(grids.GRIDS["default"])) < len(grids.cases(grids.GRIDS["full"]))


def test_resolution_override_sets_line_length():
    from pipeline.synth import scene_from

    for length in (120.0, 300.0, 650.0, 1300.0):
        scene = scene_from("lab", **dict(grids.scene_overrides("line_length_px", length)))
        assert grids.L0_MM / scene.mm_per_px == pytest.approx(length, rel=0.01)


def test_unknown_grid_is_a_user_error():
    from pipeline.errors import UserInputError

    with pytest.raises(UserInputError, match="--grid"):
        grids.get_grid("huge")


# ---------------------------------------------------------------------------------------------
# end to end: a tiny grid through the real renderer, every method, the CLI, charts and pages

TINY = grids.Grid(
    "default",
    (
        grids.Sweep("psi", "true bending angle psi (deg)", "psi_deg", (0.0, 150.0), 0.0),
        grids.Sweep("bulge", "bulge", "bulge", (0.0, 0.6), 0.0, psis_deg=(-120.0,)),
    ),
    repeat_psis_deg=(60.0,),
    repeat_seeds=2,
)


def test_run_is_deterministic_across_jobs():
    from pipeline.study.run import run_grid

    cs = grids.cases(TINY)[:2]
    a = run_grid(cs, methods=["hyper", "turning"], jobs=1)
    b = run_grid(cs, methods=["hyper", "turning"], jobs=2)
    cols = ["case_id", "method", "psi_deg", "status", "degree"]
    pd.testing.assert_frame_equal(a[cols], b[cols])
    assert (a["seconds"] > 0).all() and (a["decode_seconds"] > 0).all()


def test_bench_cli_end_to_end(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
):
    from pipeline.bench import study
    from pipeline.measure import METHODS
    from pipeline.study import pages

    monkeypatch.setitem(grids.GRIDS, "default", TINY)
    out = tmp_path / "bench"
    args = argparse.Namespace(grid="default", jobs=2, out=out, methods=None, seed=1, no_model=False)
    assert study.run(args) == 0
    printed = capsys.readouterr().out
    assert "Nominal scenes" in printed and "Breakdown point" in printed and "grid_n" in printed
    n_images = len(grids.cases(TINY))
    res = pd.read_csv(out / "results.csv")
    assert len(res) == n_images * len(METHODS)
    assert set(res["method"]) == set(METHODS)
    ok = res["psi_deg"].notna()
    assert np.allclose(
        res.loc[ok, "error_deg"], res.loc[ok, "psi_deg"] - res.loc[ok, "psi_true_deg"], atol=1e-4
    )
    # the adaptive method's model choice is recorded for every image it measured
    for method in ("turning", "auto"):
        trn = res[(res["method"] == method) & ok]
        assert trn["degree"].notna().all() and (trn["degree"] >= 1).all()
    sa = pd.read_csv(out / "speed_accuracy.csv")
    assert set(sa["condition"]) == {"nominal", "psi", "bulge"}
    assert sa.groupby("condition")["pareto"].any().all()
    stab = pd.read_csv(out / "stability.csv")
    assert len(stab) == 4 * len(METHODS)
    bd = pd.read_csv(out / "breakdown.csv")
    assert len(bd) == 2 * len(METHODS)
    rep = pd.read_csv(out / "repeatability.csv")
    assert (rep["n_seeds"] == 2).all() and len(rep) == len(METHODS)
    choice = pd.read_csv(out / "model_choice.csv")
    assert set(choice["bulge"]) == {0.0, 0.6} and set(choice["method"]) == {"turning", "auto"}
    cost = pd.read_csv(out / "model_cost.csv")
    assert list(cost.columns[:3]) == ["grid_n", "seconds", "max_rel_error"] and len(cost) >= 3
    for stem in ("speed_accuracy", "stability", "tables", "model_cost"):
        assert (out / f"{stem}.pdf").read_bytes()[:4] == b"%PDF"
        assert (out / f"{stem}.png").stat().st_size > 1000
    figs = pages.figures(out)
    assert len(figs) == 4
    assert pages.figures(tmp_path / "missing") == []
    _assert_same_as_measure_photoset(res, tmp_path / "photoset")


def _assert_same_as_measure_photoset(res: pd.DataFrame, folder: Path) -> None:
    """The bench's psi for the default method is what ``measure_photoset`` gives on the same
    JPEGs."""
    from pipeline.measure import DEFAULT_METHOD
    from pipeline.photoset import write_manifest, write_settings
    from pipeline.photoset_measure import measure_photoset
    from pipeline.study.run import render_case

    cases = grids.cases(TINY)
    folder.mkdir()
    rows = []
    for case in cases:
        scene, rendered = render_case(case)
        image = f"case_{case.case_id:03d}.jpg"
        (folder / image).write_bytes(rendered.jpeg_bytes)
        rows.append(
            {
                "image": image,
                "pressure_kpa": float(case.case_id),
                "direction": "up",
                "material": "synthetic",
                "actuator": "A1",
                "trial": "1",
                "step": case.case_id,
                "mm_per_px": scene.mm_per_px,
                "line_color": scene.line_color,
                "fixed_end_x": rendered.fixed_end_px[0],
                "fixed_end_y": rendered.fixed_end_px[1],
            }
        )
    write_settings(folder, {"l0_mm": TINY.l0_mm, "positive_turn": "ccw"})
    write_manifest(folder, pd.DataFrame(rows))
    # bench cases are no ramp
    angles = measure_photoset(folder, method=DEFAULT_METHOD, ramp_check=False)
    bench = (
        res[res["method"] == DEFAULT_METHOD].set_index("case_id").loc[[c.case_id for c in cases]]
    )
    assert angles["status"].tolist() == bench["status"].tolist()
    assert angles["degree"].astype(float).tolist() == bench["degree"].tolist()
    # results.csv holds 8 significant digits
    np.testing.assert_allclose(
        angles["psi_deg"].to_numpy(float), bench["psi_deg"].to_numpy(float), rtol=1e-7, atol=1e-9
    )
