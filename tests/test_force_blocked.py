"""Blocked-force photos: synthetic sets (pipeline.force.synth_blocked), eccentricity measurement
(pipeline.force.blocked), the force CLI and the report pages (pipeline.force.pages)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

from pipeline.cli import main
from pipeline.force.blocked import RESULT_COLUMNS, measure_blocked_image, measure_blocked_photoset
from pipeline.force.ellipse import fit_ellipse
from pipeline.force.pages import figures
from pipeline.force.synth_blocked import (
    blocked_arc_mm,
    blocked_eccentricity,
    blocked_force_n,
    blocked_ramp_table,
    render_blocked_photoset,
)
from pipeline.measure.settings import resolve_settings


def drawn_arc_image(
    e: float, *, gap_deg: float = 0.0, mm_per_px: float = 0.3, offset_px=(0, 0), seed: int = 0
) -> np.ndarray:
    """A plain photo of a blocked line drawn with OpenCV (independent of pipeline.synth)."""
    shape = blocked_arc_mm(e, 270.0, arc_fraction=0.58, gap_deg=gap_deg)
    p = shape.points_mm / mm_per_px
    p[:, 1] *= -1
    p += (
        np.array([640.0, 480.0])
        - (p.min(axis=0) + p.max(axis=0)) / 2
        + np.asarray(offset_px, float)
    )
    img = np.full((960, 1280, 3), 205, np.uint8)
    cv2.polylines(
        img, [np.round(p * 16).astype(np.int32)], False, (25, 25, 25), 6, cv2.LINE_AA, shift=4
    )
    img = cv2.GaussianBlur(img, (0, 0), 0.8)
    noise = np.random.default_rng(seed).normal(0.0, 3.0, img.shape)
    return np.clip(img + noise, 0, 255).astype(np.uint8)


# ----------------------------------------------------------------------------- synthetic shapes


@pytest.mark.parametrize("e", [0.0, 0.4, 0.8])
@pytest.mark.parametrize("gap_deg", [0.0, 60.0])
def test_blocked_arc_has_length_l0_and_the_eccentricity(e: float, gap_deg: float) -> None:
    shape = blocked_arc_mm(e, 270.0, arc_fraction=0.6, gap_deg=gap_deg)
    pts = shape.points_mm
    assert np.sum(np.hypot(*np.diff(pts, axis=0).T)) == pytest.approx(270.0, rel=1e-3)
    assert np.allclose(pts[0], 0.0)
    start = pts[1] - pts[0]
    assert abs(np.arctan2(start[1], start[0])) < 1e-6  # leaves the clamp along +x
    fit = fit_ellipse(pts)
    assert fit.eccentricity == pytest.approx(e, abs=2e-3)
    assert fit.arc_fraction == pytest.approx(0.6, abs=5e-3)
    assert fit.semi_major_px == pytest.approx(shape.semi_major_mm, rel=1e-3)


def test_force_and_eccentricity_curves_pass_the_paper_values() -> None:
    assert blocked_force_n("DS20", 105.0) == pytest.approx(2.7)
    assert blocked_force_n("DS30", 112.0) == pytest.approx(2.1)
    assert blocked_force_n("SS40", 210.0) == pytest.approx(5.1)
    assert blocked_force_n("SS50", 210.0) == pytest.approx(1.6)
    for material, e in {"DS20": 0.6, "DS30": 0.5, "SS40": 0.55, "SS50": 0.4}.items():
        top = {"DS20": 105.0, "DS30": 120.0, "SS40": 210.0, "SS50": 210.0}[material]
        assert blocked_eccentricity(material, top) == pytest.approx(e)
    p = np.linspace(0, 200, 21)
    assert np.all(np.diff(blocked_force_n("SS40", p)) > 0)  # monotonic
    assert np.all(np.diff(np.diff(blocked_force_n("SS40", p))) > 0)  # non-linear (stiffening)


def test_ramp_table_is_seeded() -> None:
    a = blocked_ramp_table("DS30", actuators=2, trials=2, seed=5)
    b = blocked_ramp_table("DS30", actuators=2, trials=2, seed=5)
    c = blocked_ramp_table("DS30", actuators=2, trials=2, seed=6)
    pd.testing.assert_frame_equal(a, b)
    assert not np.allclose(a["force_n"], c["force_n"])
    assert a["pressure_kpa"].max() == 120.0 and len(a) == 2 * 2 * 13
    assert (a["force_samples"] == 10).all() and (a["force_sd_n"] > 0).all()
    # the per-step mean stays near the true force (10 samples of ~0.02-0.07 N noise)
    assert np.abs(a["force_n"] - a["force_true_n"]).max() < 0.1


# ----------------------------------------------------------------------------- one photo

SCALED = resolve_settings(l0_mm=270.0, mm_per_px=0.3)
UNSCALED = resolve_settings(l0_mm=270.0)


@pytest.mark.parametrize("e", [0.3, 0.55, 0.8])
@pytest.mark.parametrize("gap_deg", [0.0, 90.0])
def test_drawn_photo_eccentricity_within_target(e: float, gap_deg: float) -> None:
    r = measure_blocked_image(drawn_arc_image(e, gap_deg=gap_deg), SCALED)
    assert r.status == "ok", r.reason
    assert abs(r.eccentricity - e) <= 0.02
    assert r.length_px == pytest.approx(900.0, rel=0.03)
    assert r.row()["semi_major_mm"] == pytest.approx(r.fit.semi_major_px * 0.3)


def test_unreadable_and_empty_photos_fail() -> None:
    assert measure_blocked_image(None, UNSCALED).status == "failed"
    blank = np.full((200, 300, 3), 200, np.uint8)
    r = measure_blocked_image(blank, UNSCALED)
    assert r.status == "failed" and "no line" in r.reason and np.isnan(r.eccentricity)


def test_line_leaving_the_photo_is_flagged() -> None:
    r = measure_blocked_image(drawn_arc_image(0.5, offset_px=(560, 0)), SCALED)
    assert r.status == "flagged"
    assert "border" in r.reason


def test_clamp_blob_is_painted_over() -> None:
    """A dark clamp with light details at the fixed end would otherwise be followed by the
    centre-line extraction and bias e."""
    e = 0.6
    img = drawn_arc_image(e)
    shape = blocked_arc_mm(e, 270.0)
    p = shape.points_mm / 0.3
    p[:, 1] *= -1
    p += np.array([640.0, 480.0]) - (p.min(axis=0) + p.max(axis=0)) / 2
    x, y = (int(v) for v in p[0])
    cv2.rectangle(img, (x - 70, y - 35), (x, y + 35), (60, 60, 60), -1)
    cv2.rectangle(img, (x - 62, y - 27), (x - 8, y + 27), (120, 120, 120), 3)
    cv2.circle(img, (x - 35, y - 12), 7, (170, 170, 170), 2)
    cv2.circle(img, (x - 35, y + 12), 7, (170, 170, 170), 2)
    good = measure_blocked_image(img, SCALED)
    assert abs(good.eccentricity - e) <= 0.02
    assert good.status == "ok", good.reason


# ----------------------------------------------------------------------------- photo sets + CLI


@pytest.fixture(scope="module")
def blocked_set(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("blocked") / "SS40"
    render_blocked_photoset(
        out, "SS40", actuators=2, trials=1, seed=3, scene="lab", step_kpa=70.0,
        scene_overrides={"width": 960, "height": 720},
    )
    return out


def test_synthetic_set_is_a_valid_photoset_with_force_columns(blocked_set: Path) -> None:
    from pipeline.photoset import load_photoset, validate_photoset

    assert validate_photoset(blocked_set) == []
    m = load_photoset(blocked_set).manifest
    for c in ("force_n", "force_sd_n", "force_samples", "measured_pressure_kpa"):
        assert c in m.columns
    truth = pd.read_csv(blocked_set / "truth.csv")
    assert list(truth["image"]) == list(m["image"])
    assert truth["eccentricity"].max() > 0.5


def test_measured_set_matches_truth(blocked_set: Path, tmp_path: Path) -> None:
    table = measure_blocked_photoset(blocked_set, jobs=1)
    assert list(table.columns[: len(RESULT_COLUMNS)]) == list(RESULT_COLUMNS)
    assert {"pressure_kpa", "force_n", "force_sd_n", "material", "image_path"} <= set(table.columns)
    truth = pd.read_csv(blocked_set / "truth.csv")
    merged = table.merge(truth[["image", "eccentricity"]], on="image", suffixes=("", "_true"))
    check = merged[merged["eccentricity_true"] >= 0.3]
    assert len(check) >= 4
    assert (check["status"] == "ok").all(), check["reason"].tolist()
    assert np.abs(check["eccentricity"] - check["eccentricity_true"]).max() <= 0.02


def test_missing_image_is_one_failed_row(blocked_set: Path, tmp_path: Path) -> None:
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(blocked_set, copy)
    first = pd.read_csv(copy / "manifest.csv")["image"].iloc[-1]
    (copy / first).unlink()
    table = measure_blocked_photoset(copy)
    row = table.set_index("image").loc[first]
    assert row["status"] == "failed" and "not found" in row["reason"]
    assert (table["status"] != "failed").sum() == len(table) - 1


def test_cli_end_to_end_and_pages(
    blocked_set: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    force_dir = tmp_path / "force"
    ecc = tmp_path / "eccentricity.csv"
    assert main(["force", "measure", str(blocked_set), "--out", str(ecc), "--jobs", "2"]) == 0
    assert (
        main(["force", "aggregate", str(ecc), "--out", str(force_dir / "force_summary.csv")]) == 0
    )
    assert main(["force", "grasp", "--example", "--out", str(force_dir / "grasp_summary.csv")]) == 0
    out = capsys.readouterr().out
    assert "force measure:" in out and "force aggregate:" in out and "force grasp:" in out
    summary = pd.read_csv(force_dir / "force_summary.csv")
    assert set(summary["material"]) == {"SS40"}
    assert summary["n"].eq(2).all()
    e = pd.read_csv(force_dir / "eccentricity_summary.csv")
    truth = pd.read_csv(blocked_set / "truth.csv")
    top = truth[truth["pressure_kpa"] == truth["pressure_kpa"].max()]["eccentricity"].mean()
    assert e.loc[0, "eccentricity_mean"] == pytest.approx(top, abs=0.02)
    assert Path(e.loc[0, "image_path"]).is_file()
    figs = figures(force_dir)
    assert len(figs) == 3
    labels = [ax.get_xlabel() for f in figs for ax in f.axes]
    assert "pressure (kPa)" in labels
    assert any("(N)" in ax.get_ylabel() for ax in figs[0].axes)
    assert main(["force", "pages", str(force_dir), "--out", str(tmp_path / "p.pdf")]) == 0
    assert (tmp_path / "p.pdf").stat().st_size > 1000


def test_cli_bad_input_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "log.csv"
    bad.write_text("material,object,side,diameter_mm,mass_g,pressure_kpa,held\nDS20,x,inside,90,700,20,perhaps\n")
    assert main(["force", "grasp", str(bad), "--out", str(tmp_path / "g.csv")]) == 2
    assert "line 2, column held" in capsys.readouterr().err
    assert (
        main(["force", "aggregate", str(tmp_path / "none.csv"), "--out", str(tmp_path / "f.csv")])
        == 2
    )
    assert main(["force", "synth", str(tmp_path / "s"), "--material", "XX99"]) == 2
    assert figures(tmp_path / "empty") == []
