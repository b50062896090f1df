"""The PDF report: builds with 1 and 4 materials and an increasing-only set, pages not blank,
identical bytes for identical inputs, bench/force pages fetched defensively."""

from __future__ import annotations

import subprocess
import sys
import types
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

from pipeline.cli import main
from pipeline.errors import UserInputError
from pipeline.report import Dataset, ReportInputs, build_report

pdfium = pytest.importorskip("pypdfium2")

#: rough p(psi=0) per material, only to make curves of the right shape
P_ZERO = {"DS20": 65.0, "DS30": 105.0, "SS40": 215.0, "SS50": 600.0}
P_MAX = {"DS20": 110.0, "DS30": 170.0, "SS40": 250.0, "SS50": 250.0}


def fake_psi(material: str, p: np.ndarray, direction: str) -> np.ndarray:
    """A Fig. 6-like curve: 210 deg at rest, falling through 0 near P_ZERO; decreasing branch lower."""
    shift = 0.85 if direction == "down" else 1.0
    x = np.asarray(p, float) / (P_ZERO[material] * shift)
    return 210.0 - 210.0 * x**2.2


def make_dataset(root: Path, material: str, *, actuators=3, trials=2, step=10.0, directions=("up", "down"),
                 photos=True, overlays=True, seed=0) -> Dataset:
    """Write angles.csv (+ a small photo set and overlays) shaped like the measure stage's outputs."""
    rng = np.random.default_rng(seed)
    folder = root / material
    photo_dir, overlay_dir = folder / "photos", folder / "overlays"
    photo_dir.mkdir(parents=True)
    overlay_dir.mkdir()
    levels = np.arange(0.0, P_MAX[material] + 1e-9, step)
    rows = []
    for a in range(1, actuators + 1):
        for t in range(1, trials + 1):
            for direction in directions:
                order = levels if direction == "up" else levels[::-1]
                for k, p in enumerate(order):
                    image = f"{material}_a{a}_t{t}_{direction}_{k:03d}.jpg"
                    psi = float(fake_psi(material, p, direction) + rng.normal(0, 6.0))
                    status, reason = "ok", ""
                    if rng.random() < 0.05:
                        status, reason, psi = "failed", "no line found", float("nan")
                    elif rng.random() < 0.05:
                        status, reason = "flagged", "high residual"
                    rows.append({"image": image, "psi_deg": psi, "kappa_per_mm": np.radians(psi) / 195.0,
                                 "length_mm": 195.0, "method": "paper", "residual_px": 0.4, "status": status,
                                 "reason": reason, "seconds": 0.02, "pressure_kpa": p, "direction": direction,
                                 "material": material, "actuator": a, "trial": t, "step": k})
                    if a == 1 and t == 1 and (photos or overlays):
                        img = np.full((120, 160, 3), 235, np.uint8)
                        ang = 0.0 if not np.isfinite(psi) else psi
                        cv2.ellipse(img, (80, 60), (40, 40), 0, 0, max(abs(ang), 5.0), (20, 20, 20), 3)
                        if photos:
                            cv2.imwrite(str(photo_dir / image), img)
                        if overlays and k % 2 == 0:  # some overlays missing: falls back to raw
                            cv2.putText(img, f"{ang:.0f}", (5, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 0, 255), 1)
                            cv2.imwrite(str(overlay_dir / (Path(image).stem + ".jpg")), img)
    pd.DataFrame(rows).to_csv(folder / "angles.csv", index=False)
    return Dataset(material, folder / "angles.csv", photo_dir if photos else None,
                   overlay_dir if overlays else None)


def model_curves(path: Path, materials) -> Path:
    psi = np.linspace(210.0, -220.0, 80)
    frames = [pd.DataFrame({"material": m, "psi_deg": psi,
                            "pressure_kpa": 1.1 * P_ZERO[m] * np.clip((210.0 - psi) / 210.0, 0, None) ** (1 / 2.2),
                            "reason": ""}) for m in materials]
    pd.concat(frames).to_csv(path, index=False)
    return path


def pipeline_tables(tmp: Path, datasets) -> tuple[list[Path], Path]:
    """Run the real aggregate and compare stages (compare with an injected model) on the datasets."""
    from pipeline.aggregate import read_angles
    from pipeline.compare import compare

    hyst = []
    for d in datasets:
        out = d.angles_csv.parent / "hysteresis.csv"
        assert main(["aggregate", str(d.angles_csv), "--out", str(out)]) == 0
        hyst.append(out)
    h = pd.concat([pd.read_csv(p) for p in hyst])
    table = compare(h, read_angles([d.angles_csv for d in datasets]),
                    model_psi=lambda m, p, l0_mm: fake_psi(m, p, "up") + 10.0, fit_k_p=None)
    rms = tmp / "rms.csv"
    table.to_csv(rms, index=False)
    return hyst, rms


def cli_in_fresh_process(args: list[str]) -> str:
    """Run ``python -m pipeline ARGS`` in a new interpreter; return stderr ('' on success)."""
    proc = subprocess.run([sys.executable, "-m", "pipeline", *args], capture_output=True, text=True, check=False)
    return "" if proc.returncode == 0 else proc.stderr or f"exit {proc.returncode}"


def page_images(pdf: Path, scale: float = 0.6) -> list[np.ndarray]:
    doc = pdfium.PdfDocument(str(pdf))
    try:
        return [np.asarray(doc[i].render(scale=scale).to_pil().convert("L")) for i in range(len(doc))]
    finally:
        doc.close()


def assert_not_blank(images) -> None:
    for i, img in enumerate(images):
        ink = float(np.mean(img < 200))
        assert ink > 0.003, f"page {i + 1} looks blank (ink {ink:.4f})"


@pytest.fixture(scope="module")
def four(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("four")
    datasets = [make_dataset(tmp, m, seed=i) for i, m in enumerate(("DS20", "DS30", "SS40", "SS50"))]
    hyst, rms = pipeline_tables(tmp, datasets)
    curves = model_curves(tmp / "curves.csv", P_ZERO)
    config = tmp / "config.yaml"
    config.write_text("datasets: []\n")
    return tmp, datasets, hyst, rms, curves, config


def test_four_materials_deterministic_and_not_blank(four, tmp_path):
    _tmp, datasets, hyst, rms, curves, config = four
    args = ["report", "--angles", *[str(d.angles_csv) for d in datasets],
            "--photosets", *[str(d.photoset_dir) for d in datasets],
            "--overlays", *[str(d.overlays_dir) for d in datasets],
            "--hysteresis", *map(str, hyst), "--rms", str(rms), "--model-curves", str(curves),
            "--config", str(config)]
    a, b = tmp_path / "a.pdf", tmp_path / "b.pdf"
    assert cli_in_fresh_process(args + ["--out", str(a)]) == ""
    assert cli_in_fresh_process(args + ["--out", str(b)]) == ""
    assert a.read_bytes() == b.read_bytes()
    raw = a.read_bytes()
    assert b"CreationDate" not in raw
    images = page_images(a)
    # summary, overview, one per material, comparison table, which model curve (l0) each used
    assert len(images) == 1 + 1 + 4 + 1 + 1
    assert_not_blank(images)
    # the config digest changes the bytes (it is printed on the summary page)
    config.write_text("datasets: [changed]\n")
    c = tmp_path / "c.pdf"
    assert cli_in_fresh_process(args + ["--out", str(c)]) == ""
    assert c.read_bytes() != raw


def test_the_summary_says_which_model_readings_were_used(tmp_path):
    from pipeline.report.data import load_report_data

    d = make_dataset(tmp_path, "SS40", photos=False, overlays=False, trials=1)
    config = tmp_path / "config.yaml"
    config.write_text("model: {readings: {l0_factor: metres, jacobian: deformed}}\n")
    notes = load_report_data(ReportInputs(datasets=(d,), config=config)).notes
    assert "readings set in the config: jacobian=deformed, l0_factor=metres" in " ".join(notes)
    config.write_text("model: {materials_file: null, readings: {}}\n")
    notes = load_report_data(ReportInputs(datasets=(d,), config=config)).notes
    assert "with the default readings" in " ".join(notes)
    config.write_text("model: [unclosed\n")
    with pytest.raises(UserInputError, match="cannot read it as YAML"):
        load_report_data(ReportInputs(datasets=(d,), config=config))


def test_one_material_without_optional_tables(tmp_path):
    d = make_dataset(tmp_path, "SS40", photos=False, overlays=False, trials=1)
    out = tmp_path / "r.pdf"
    res = build_report(ReportInputs(datasets=(d,)), out)
    assert res.materials == ("SS40",)
    images = page_images(out)
    assert len(images) == res.pages == 4
    assert_not_blank(images)
    again = tmp_path / "again.pdf"
    build_report(ReportInputs(datasets=(d,)), again)
    assert again.read_bytes() == out.read_bytes()
    # the command line (a fresh process, as Snakemake runs it) writes the same bytes as the API
    other = tmp_path / "other.pdf"
    assert cli_in_fresh_process(["report", "--angles", str(d.angles_csv), "--datasets", d.name,
                                 "--out", str(other)]) == ""
    assert other.read_bytes() == out.read_bytes()


def test_increasing_only_photoset(tmp_path):
    d = make_dataset(tmp_path, "DS20", directions=("up",), overlays=False)
    hyst, rms = pipeline_tables(tmp_path, [d])
    out = tmp_path / "r.pdf"
    res = build_report(ReportInputs(datasets=(d,), hysteresis=tuple(hyst), rms=(rms,)), out)
    assert res.pages == 5  # summary, overview, DS20, comparison, model provenance
    assert_not_blank(page_images(out))
    table = pd.read_csv(rms)
    assert np.isnan(table["rms_down_deg"].iloc[0]) and np.isfinite(table["rms_up_deg"].iloc[0])


def _fake_module(monkeypatch, name: str, figures) -> None:
    mod = types.ModuleType(name)
    mod.figures = figures
    monkeypatch.setitem(sys.modules, name, mod)


def test_extra_pages_added_and_errors_reported(tmp_path, monkeypatch, capsys):
    from matplotlib.figure import Figure

    d = make_dataset(tmp_path, "SS50", trials=1, photos=False, overlays=False)
    bench_dir, force_dir = tmp_path / "bench", tmp_path / "force"
    bench_dir.mkdir()
    force_dir.mkdir()

    def bench_figures(folder: Path):
        assert folder == bench_dir
        fig = Figure(figsize=(8.27, 11.69))
        ax = fig.subplots()
        ax.plot([0, 1], [0, 1])
        ax.set_xlabel("x (px)")
        return [fig]

    def broken(folder: Path):
        raise RuntimeError("force table is corrupt")

    _fake_module(monkeypatch, "pipeline.bench.pages", bench_figures)
    _fake_module(monkeypatch, "pipeline.force.pages", broken)
    out = tmp_path / "r.pdf"
    res = build_report(ReportInputs(datasets=(d,), bench_dir=bench_dir, force_dir=force_dir), out)
    assert res.pages == 5  # summary, overview, SS50, table, bench
    assert any("force table is corrupt" in w for w in res.warnings)
    doc = pdfium.PdfDocument(str(out))
    summary_text = " ".join(doc[0].get_textpage().get_text_range().split())
    doc.close()
    assert "WARNING: pipeline.force.pages.figures" in summary_text
    assert "RuntimeError: force table is corrupt" in summary_text
    assert "force table is corrupt" in capsys.readouterr().err  # traceback on stderr too


def test_missing_module_adds_no_pages(tmp_path, monkeypatch):
    from pipeline.report.extra import extra_pages

    monkeypatch.setitem(sys.modules, "pipeline.nonexistent_stage", None)
    res = extra_pages("pipeline.nonexistent_stage.pages", tmp_path)
    assert res.figures == [] and res.warnings == [] and res.infos
    assert extra_pages("pipeline.bench.pages", None).figures == []
    assert extra_pages("pipeline.bench.pages", tmp_path / "absent").warnings


def test_bad_inputs_exit_2(four, tmp_path):
    _tmp, datasets, *_ = four
    out = str(tmp_path / "r.pdf")
    assert main(["report", "--angles", str(datasets[0].angles_csv), "--photosets", "a", "b", "--out", out]) == 2
    assert main(["report", "--angles", str(tmp_path / "missing.csv"), "--out", out]) == 2
    assert main(["report", "--angles", str(datasets[0].angles_csv), "--rms", str(datasets[0].angles_csv),
                 "--model-curves", str(datasets[0].angles_csv), "--out", out]) == 2


def test_a_re_measured_set_that_differs_only_in_timings_gives_the_same_pdf(tmp_path):
    """angles.csv records seconds per photo; two runs on the same photos (a workstation and a
    cluster) differ only there, and the report (which prints the table's digest) must not.
    The pages are pure functions of ReportData, so equal data means equal bytes (the SLURM test
    compares whole PDFs)."""
    from pipeline.report.data import load_report_data, sha256_file, sha256_measurements

    d = make_dataset(tmp_path, "SS40", photos=False, overlays=False, trials=1)
    first = load_report_data(ReportInputs(datasets=(d,))).digests
    angles = pd.read_csv(d.angles_csv)
    angles.assign(seconds=angles["seconds"] * 3.7 + 0.011).to_csv(d.angles_csv, index=False)
    assert load_report_data(ReportInputs(datasets=(d,))).digests == first
    digest = sha256_measurements(d.angles_csv)
    angles.assign(psi_deg=angles["psi_deg"] + 0.001).to_csv(d.angles_csv, index=False)
    assert sha256_measurements(d.angles_csv) != digest
    angles.drop(columns="seconds").to_csv(d.angles_csv, index=False)
    assert sha256_measurements(d.angles_csv) == sha256_file(d.angles_csv)
