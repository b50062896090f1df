"""Tests of the speed / accuracy comparison in :mod:`pipeline.bench.measure` (issue 6's target).

The comparison runs for real on a few small synthetic photos (scikit-image provides the
skeletonize baseline); the verdict rule is checked as a pure function on made-up tables.
"""

from __future__ import annotations

import cv2
import numpy as np
import pandas as pd
import pytest

from pipeline.bench import measure as bench

SPEED_COLUMNS = ["n", "imread_ms", "ours_ms", "ours/imread", "skeleton_ms", "skeleton/ours",
                 "decode_floor_ms", "bare_ms", "max_speedup"]
PAIRED_COLUMNS = [
    "size",
    "tilt_deg",
    "n",
    "ours_med_err",
    "ours_|psi|_med_err",
    "skel_|psi|_med_err",
    "med_diff",
    "ci_lo",
    "ci_hi",
    "ours_as_good",
]


@pytest.fixture(scope="module")
def small_run(tmp_path_factory: pytest.TempPathFactory) -> pd.DataFrame:
    return bench.speed(
        2, seed=3, workdir=tmp_path_factory.mktemp("speed"), sizes=((640, 480),), repeats=1
    )


def test_speed_renders_each_image_at_tilt_0_and_lab_tilt(small_run: pd.DataFrame) -> None:
    assert len(small_run) == 4
    assert sorted(small_run["tilt_deg"].unique()) == [0.0, 1.0]
    per_image = small_run.groupby("image")
    # same psi and the same timings on both tilts of one image
    assert (per_image["psi_true"].nunique() == 1).all()
    assert (per_image["ours_s"].nunique() == 1).all()
    assert small_run["psi_true"].nunique() == 2
    # the baseline gives |psi| only; both methods measure something near the truth on clean lab
    # photos
    assert (small_run["skeleton_psi"] >= 0).all()
    assert (small_run["ours_status"] == "ok").all()
    assert (small_run["ours_abs_err"] < 2.0).all()
    np.testing.assert_allclose(small_run["ours_absmag_err"],
                               (small_run["ours_psi"].abs() - small_run["psi_true"].abs()).abs())
    np.testing.assert_allclose(small_run["skeleton_absmag_err"],
                               (small_run["skeleton_psi"] - small_run["psi_true"].abs()).abs())


def test_speed_table_columns_and_ratios(small_run: pd.DataFrame) -> None:
    tab = bench.speed_table(small_run)
    assert list(tab.columns) == SPEED_COLUMNS
    assert list(tab.index) == ["640x480"]
    assert tab.loc["640x480", "n"] == 2
    values = tab.drop(columns="n").to_numpy(float)
    assert np.all(np.isfinite(values)) and np.all(values > 0)
    row = tab.loc["640x480"]
    assert row["max_speedup"] == pytest.approx(row["skeleton_ms"] / row["decode_floor_ms"])


def test_paired_accuracy_columns_and_ci(small_run: pd.DataFrame) -> None:
    paired = bench.paired_accuracy(small_run, seed=0, resamples=200)
    assert list(paired.columns) == PAIRED_COLUMNS
    assert list(paired["tilt_deg"]) == [0.0, 1.0]
    for _, row in paired.iterrows():
        assert row["ci_lo"] <= row["med_diff"] <= row["ci_hi"]
        assert 0.0 <= row["ours_as_good"] <= 1.0
        assert np.isfinite(
            row[["ours_|psi|_med_err", "skel_|psi|_med_err", "med_diff"]].to_numpy(float)
        ).all()


def test_print_speed_prints_tables_and_verdicts(
    small_run: pd.DataFrame, capsys: pytest.CaptureFixture[str]
) -> None:
    bench.print_speed(small_run, seed=0)
    out = capsys.readouterr().out
    assert "decode_floor_ms" in out and "ci_hi" in out
    assert "640x480: 10x at equal or better accuracy: " in out
    assert "CI upper bound" in out


def _made_up_sp(
    ours_s: float, skel_s: float, ours_err: np.ndarray, skel_err: np.ndarray
) -> pd.DataFrame:
    """A :func:`bench.speed`-like frame: 12 images x 2 tilts at one size."""
    n = ours_err.size
    rows = []
    for tilt in (0.0, 1.0):
        for i in range(n):
            rows.append(
                {
                    "size": "100x100",
                    "image": i,
                    "tilt_deg": tilt,
                    "psi_true": 50.0,
                    "ours_psi": 50.0 + ours_err[i],
                    "ours_status": "ok",
                    "skeleton_psi": 50.0 + skel_err[i],
                    "ours_abs_err": abs(ours_err[i]),
                    "ours_absmag_err": abs(ours_err[i]),
                    "skeleton_absmag_err": abs(skel_err[i]),
                    "imread_s": 0.001,
                    "ours_s": ours_s,
                    "skeleton_s": skel_s,
                    "decode_floor_s": 0.0005,
                    "bare_s": 0.0006,
                }
            )
    return pd.DataFrame(rows)


def _verdict(sp: pd.DataFrame) -> str:
    return bench.verdicts(
        bench.speed_table(sp), bench.paired_accuracy(sp, seed=0, resamples=500)
    ).loc["100x100"]


@pytest.mark.parametrize(
    ("ours_s", "skel_s", "ours_sd", "skel_sd", "expected"),
    [
        (0.001, 0.020, 0.02, 0.5, "met"),  # 20x faster and more accurate
        (0.020, 0.010, 0.02, 0.5, "not met"),  # slower
        (0.001, 0.020, 0.5, 0.02, "not met"),  # fast but less accurate
    ],
    ids=["20x-and-more-accurate", "slower", "fast-but-less-accurate"],
)
def test_verdict(
    ours_s: float, skel_s: float, ours_sd: float, skel_sd: float, expected: str
) -> None:
    rng = np.random.default_rng(0)
    sp = _made_up_sp(ours_s, skel_s, rng.normal(0, ours_sd, 12), rng.normal(0, skel_sd, 12))
    assert _verdict(sp) == expected


def test_failed_measurement_counts_as_worse() -> None:
    rng = np.random.default_rng(3)
    sp = _made_up_sp(0.001, 0.020, rng.normal(0, 0.02, 12), rng.normal(0, 0.5, 12))
    sp["ours_absmag_err"] = np.nan  # every measurement of ours failed
    paired = bench.paired_accuracy(sp, seed=0, resamples=100)
    assert (paired["ours_as_good"] == 0.0).all()
    assert (paired["med_diff"] == np.inf).all()
    assert bench.verdicts(bench.speed_table(sp), paired).loc["100x100"] == "not met"


def test_verdict_threshold_is_on_the_ci_upper_bound() -> None:
    tab = pd.DataFrame({"skeleton/ours": [12.0, 12.0]}, index=pd.Index(["a", "b"], name="size"))
    paired = pd.DataFrame({"size": ["a", "a", "b", "b"], "tilt_deg": [0.0, 1.0, 0.0, 1.0],
                           "ci_hi": [0.009, 5.0, 0.011, -1.0]})
    assert bench.verdicts(tab, paired).to_dict() == {"a": "met", "b": "not met"}


def test_scaling_measures_both_job_counts_and_the_pool_start_up(tmp_path) -> None:
    out = bench.scaling(2, seed=3, workdir=tmp_path, copies=2, size=(640, 480))
    assert set(out) == {"jobs=1", "jobs=2", "start-up, jobs=2"}
    assert all(np.isfinite(v) and v > 0 for v in out.values())
    angles = pd.read_csv(tmp_path / "set" / "manifest.csv")
    assert len(angles) == 4  # 2 renders x 2 copies


def test_bare_path_fits_the_dark_arc() -> None:
    img = np.full((960, 1280), 220, np.uint8)
    cv2.ellipse(img, (640, 480), (300, 300), 0, 200, 340, 20, 24)  # dark arc, radius 300 px
    ok, buf = cv2.imencode(".jpg", img)
    assert ok
    assert bench._bare_circle_px(buf) * 4 == pytest.approx(300.0, rel=0.03)  # decoded at 1/4
