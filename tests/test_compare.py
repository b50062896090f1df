"""Model-versus-data comparison: RMS, crossings, range, hysteresis width, k_P bootstrap."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from pipeline.compare import (
    PAPER_VALUES,
    RMS_COLUMNS,
    bootstrap_k_p,
    compare,
    crossing_kpa,
    hysteresis_width,
    rms_deg,
)
from pipeline.errors import UserInputError


def _hyst() -> pd.DataFrame:
    # up: 200, 100, -50 at 0, 10, 20 kPa; down: 190, 20, -50
    rows = [
        ("up", 0, 200.0),
        ("up", 10, 100.0),
        ("up", 20, -50.0),
        ("down", 0, 190.0),
        ("down", 10, 20.0),
        ("down", 20, -50.0),
    ]
    return pd.DataFrame(
        [
            {
                "material": "DS20",
                "direction": d,
                "pressure_kpa": p,
                "psi_mean_deg": s,
                "psi_sd_deg": 1.0,
                "n": 3,
                "n_actuators": 3,
                "n_trials": 3,
                "n_excluded": 0,
            }
            for d, p, s in rows
        ]
    )


def linear_model(material: str, pressure_kpa: np.ndarray, l0_mm=None) -> np.ndarray:
    return 200.0 - 10.0 * np.asarray(pressure_kpa, float)


def test_rms_hand_computed():
    out = compare(_hyst(), model_psi=linear_model, fit_k_p=None, psi0_deg={"DS20": 40.0}).iloc[0]
    # residuals up: 0, 0, -50; down: -10, -80, -50
    assert out["rms_up_deg"] == pytest.approx(math.sqrt(2500 / 3))
    assert out["rms_down_deg"] == pytest.approx(math.sqrt(9000 / 3))
    assert out["rms_deg"] == pytest.approx(math.sqrt(11500 / 6))
    assert out["n_levels"] == 6 and out["n_model_nan"] == 0
    assert list(out.index) == list(RMS_COLUMNS)
    assert out["paper_rms_deg"] == PAPER_VALUES["DS20"].rms_deg and out["k_p_paper"] == 3.8


def test_rms_skips_model_nan():
    def partial(material, p, l0_mm):
        p = np.asarray(p, float)
        return np.where(p > 15, np.nan, linear_model(material, p))

    out = compare(_hyst(), model_psi=partial, fit_k_p=None).iloc[0]
    assert out["n_model_nan"] == 2
    assert out["rms_deg"] == pytest.approx(math.sqrt((0 + 0 + 100 + 6400) / 4))
    assert rms_deg([1.0, np.nan], [np.nan, 2.0]) == (pytest.approx(math.nan, nan_ok=True), 0, 1)


def test_crossings_both_branches():
    out = compare(_hyst(), model_psi=None, fit_k_p=None, psi0_deg={"DS20": 40.0}).iloc[0]
    assert out["p_zero_up_kpa"] == pytest.approx(10 + 10 * 100 / 150)
    assert out["p_zero_down_kpa"] == pytest.approx(20 - 10 * 50 / 70)  # walked from 20 kPa down
    assert out["p_minus_psi0_up_kpa"] == pytest.approx(10 + 10 * 140 / 150)
    assert out["p_minus_psi0_down_kpa"] == pytest.approx(20 - 10 * 10 / 70)
    assert math.isnan(out["rms_deg"])  # no model given
    # never reached, exact hit, NaN point skipped, first crossing wins
    assert math.isnan(crossing_kpa([0, 10], [200.0, 100.0], 0.0))
    assert crossing_kpa([0, 10, 20], [50.0, 0.0, -50.0], 0.0) == 10.0
    assert crossing_kpa([0, 10, 20], [50.0, np.nan, -50.0], 0.0) == pytest.approx(10.0)
    assert crossing_kpa([0, 10, 20, 30], [10.0, -10.0, 10.0, -10.0], 0.0) == pytest.approx(5.0)


def test_range_and_hysteresis_width():
    out = compare(_hyst(), model_psi=None, fit_k_p=None).iloc[0]
    assert (out["range_deg"], out["psi_max_deg"], out["psi_min_deg"], out["range_kpa"]) == (
        250.0,
        200.0,
        -50.0,
        20.0,
    )
    assert hysteresis_width(_hyst()) == (80.0, 10.0)
    up_only = _hyst()[_hyst()["direction"] == "up"]
    w, at = hysteresis_width(up_only)
    assert math.isnan(w) and math.isnan(at)
    out = compare(up_only, model_psi=linear_model, fit_k_p=None).iloc[0]
    assert math.isnan(out["rms_down_deg"]) and math.isnan(out["p_zero_down_kpa"])
    assert out["rms_deg"] == pytest.approx(out["rms_up_deg"])


def _g(psi):
    return (200.0 - np.asarray(psi, float)) / 10.0


def ls_fit(material, p, psi, l0_mm=None):
    """k minimising sum (P - k g(psi))^2, a stand-in for the model's fit."""
    g = _g(psi)
    return float(g @ p / (g @ g)), None


def _rows(k_by_actuator):
    psi = np.array([200.0, 150.0, 100.0, 50.0, 0.0, -50.0])
    return pd.concat(
        [
            pd.DataFrame({"actuator": a, "pressure_kpa": k * _g(psi), "psi_deg": psi})
            for a, k in k_by_actuator.items()
        ],
        ignore_index=True,
    )


def test_bootstrap_k_p_over_actuators():
    rows = _rows({"1": 1.0, "2": 2.0, "3": 3.0})
    k, lo, hi, n = bootstrap_k_p("DS20", rows, ls_fit, n_boot=300, seed=4)
    assert k == pytest.approx(2.0)
    assert 1.0 <= lo < k < hi <= 3.0 and n == 300
    assert bootstrap_k_p("DS20", rows, ls_fit, n_boot=300, seed=4) == (k, lo, hi, n)  # seeded
    calls = []

    def counting(material, p, psi):
        calls.append(1)
        return ls_fit(material, p, psi)

    bootstrap_k_p("DS20", rows, counting, n_boot=300, seed=5)
    assert len(calls) <= 1 + 10  # 10 distinct multisets of 3 actuators
    # one actuator: no interval
    k1, lo1, hi1, n1 = bootstrap_k_p("DS20", _rows({"1": 1.5}), ls_fit, n_boot=50, seed=0)
    assert k1 == pytest.approx(1.5) and math.isnan(lo1) and math.isnan(hi1) and n1 == 0


def test_compare_fits_k_p_from_angles_rows():
    rows = _rows({"a": 2.0, "b": 2.0})
    angles = rows.assign(status="ok", material="DS20", direction="up", trial=1)
    angles.loc[0, "status"] = "failed"
    angles.loc[0, "psi_deg"] = np.nan
    out = compare(_hyst(), angles, model_psi=linear_model, fit_k_p=ls_fit, n_boot=20, seed=1).iloc[
        0
    ]
    assert out["k_p_fit"] == pytest.approx(2.0)
    assert out["k_p_ci_low"] == pytest.approx(2.0) and out["k_p_ci_high"] == pytest.approx(2.0)
    assert out["n_actuators"] == 2


def test_unknown_material_keeps_data_metrics():
    def model(material, p, l0_mm):
        raise UserInputError(f"no material {material!r}")

    h = _hyst().assign(material="EcoFlex")
    with pytest.warns(UserWarning, match="EcoFlex"):
        out = compare(h, model_psi=model, fit_k_p=None).iloc[0]
    assert (
        math.isnan(out["rms_deg"])
        and out["range_deg"] == 250.0
        and math.isnan(out["paper_rms_deg"])
    )
    # P at psi = -psi0 from its own rest angle (200 deg at 0 kPa rising), not the paper's 210
    assert out["psi0_deg"] == 200.0 and "psi0 200.0 deg: its rest angle, measured" in out["note"]


def test_one_level_measured_gives_no_range_and_no_measured_rest_angle():
    # customer 54: one ok photo, at 125 kPa down: rms.csv said range 0 deg and "psi0 210.0 deg:
    # its rest angle, measured" (the paper's 210, nothing measured at rest)
    h = _hyst().assign(material="PN110")
    one = h[(h["direction"] == "down") & (h["pressure_kpa"] == 10)]
    out = compare(one, model_psi=None, fit_k_p=None).iloc[0]
    assert math.isnan(out["range_deg"]) and math.isnan(out["range_kpa"])
    assert "psi0 210.0 deg: the paper's: no rising curve measured" in out["note"]
    rising = h[(h["direction"] == "up") & (h["pressure_kpa"] > 0)]
    out = compare(rising, model_psi=None, fit_k_p=None).iloc[0]
    assert "psi0 100.0 deg: its psi at 10 kPa, the lowest measured on its rising curve" in (
        out["note"]
    )


def test_bad_hysteresis_table():
    with pytest.raises(UserInputError, match="missing column"):
        compare(_hyst().drop(columns="psi_mean_deg"), model_psi=None, fit_k_p=None)
    with pytest.raises(UserInputError, match="direction"):
        compare(_hyst().replace({"direction": {"up": "rising"}}), model_psi=None, fit_k_p=None)


def test_two_datasets_of_one_material_are_pooled():
    one = compare(_hyst(), model_psi=linear_model, fit_k_p=None).iloc[0]
    two = compare(pd.concat([_hyst(), _hyst()]), model_psi=linear_model, fit_k_p=None).iloc[0]
    for column in ("rms_deg", "rms_up_deg", "p_zero_down_kpa", "range_deg", "hysteresis_width_deg"):
        assert two[column] == pytest.approx(one[column])


def test_k_p_is_fitted_to_the_rising_leg_the_model_describes(tmp_path):
    # the model is the loading branch; a falling leg that lags it by hysteresis pulled a fit over
    # both legs low: the synthetic DS20 sets, rendered with k_P 3.8, fitted 3.32 and a bootstrap
    # interval that excluded 3.8. Angles drawn from the model (SS40, k_P 2.2) on the way up and
    # 25 deg lower on the way down: the rising-leg fit recovers 2.2, both legs do not.
    from pipeline import model
    from pipeline.cli import main

    p = np.arange(0.0, 251.0, 10.0)
    truth = model.psi_deg("SS40", p)
    keep = np.isfinite(truth)
    rows = [
        {"image": f"{a}_{d}_{pk:g}.jpg", "psi_deg": float(s - (25.0 if d == "down" else 0.0)),
         "status": "ok", "pressure_kpa": pk, "direction": d, "material": "SS40", "actuator": a,
         "trial": 1}
        for a in ("1", "2") for d in ("up", "down") for pk, s in zip(p[keep], truth[keep])
    ]
    angles, hyst, rms = tmp_path / "angles.csv", tmp_path / "h.csv", tmp_path / "rms.csv"
    pd.DataFrame(rows).to_csv(angles, index=False)
    assert main(["aggregate", str(angles), "--out", str(hyst)]) == 0
    assert main(["compare", str(hyst), "--angles", str(angles), "--out", str(rms)]) == 0
    out = pd.read_csv(rms).iloc[0]
    assert out["k_p_fit"] == pytest.approx(2.2, abs=0.02)
    assert out["k_p_fit_both"] < 2.2 - 0.1


def test_cli_with_the_real_model(tmp_path, capsys):
    """Angles drawn from the model itself (SS40, k_P 2.2) + 2 deg noise: small RMS, k_P ~ 2.2."""
    from pipeline import model
    from pipeline.cli import main

    rng = np.random.default_rng(7)
    p = np.arange(0.0, 251.0, 10.0)
    truth = model.psi_deg("SS40", p)
    rows = []
    for actuator in ("1", "2", "3"):
        for trial in (1, 2):
            for direction, order in (("up", p), ("down", p[::-1])):
                for pk in order:
                    psi = float(truth[p == pk][0] + rng.normal(0.0, 2.0))
                    rows.append(
                        {
                            "image": f"{actuator}_{trial}_{direction}_{pk:g}.jpg",
                            "psi_deg": psi,
                            "status": "ok",
                            "reason": "",
                            "pressure_kpa": pk,
                            "direction": direction,
                            "material": "SS40",
                            "actuator": actuator,
                            "trial": trial,
                        }
                    )
    angles = tmp_path / "angles.csv"
    pd.DataFrame(rows).to_csv(angles, index=False)
    hyst, rms = tmp_path / "h.csv", tmp_path / "rms.csv"
    assert main(["aggregate", str(angles), "--out", str(hyst)]) == 0
    assert (
        main(["compare", str(hyst), "--angles", str(angles), "--out", str(rms), "--seed", "3"]) == 0
    )
    assert "compare: SS40, l0 255 mm [" in capsys.readouterr().out
    out = pd.read_csv(rms).iloc[0]
    finite = np.isfinite(truth)
    assert out["n_model_nan"] == 2 * int((~finite).sum())
    assert out["rms_deg"] < 2.0  # mean of 6 draws of sd 2 deg
    assert out["k_p_ci_low"] <= out["k_p_fit"] <= out["k_p_ci_high"]
    assert abs(out["k_p_fit"] - 2.2) < 0.1
    assert out["p_zero_up_kpa"] == pytest.approx(crossing_kpa(p, truth, 0.0), abs=3.0)
    # the model's own crossing, on its fine grid: where the noiseless truth crosses
    assert out["model_p_zero_kpa"] == pytest.approx(crossing_kpa(p, truth, 0.0), abs=1.0)
    assert main(["compare", str(tmp_path / "missing.csv"), "--out", str(rms)]) == 2
    # another reading of the model reaches the comparison: the printed Jacobian (jacobian=none)
    # is about 15 % softer, so data drawn from the default model need a larger k_P
    other = tmp_path / "rms_printed.csv"
    assert (
        main(
            [
                "compare",
                str(hyst),
                "--angles",
                str(angles),
                "--out",
                str(other),
                "--seed",
                "3",
                "--jacobian",
                "none",
            ]
        )
        == 0
    )
    printed = pd.read_csv(other).iloc[0]
    assert printed["k_p_fit"] > out["k_p_fit"] * 1.1 and printed["rms_deg"] > out["rms_deg"]
    assert main(["compare", str(hyst), "--out", str(other), "--eq12-scale", "-1"]) == 2
    # no l0_mm in this angles.csv: the model's default l0, and rms.csv says where it came from
    assert (
        out["l0_mm"] == model.load_materials()["SS40"].l0_mm
        and out["l0_source"] == "materials file"
    )
    assert out["rms_kind"] == "unknown" and out["model_fit"].startswith("none")


def _angles(dataset: str, material: str, l0_mm, psi_offset: float = 0.0) -> pd.DataFrame:
    p = np.array([0.0, 10.0, 20.0])
    rows = [
        {
            "dataset": dataset,
            "image": f"{dataset}_{a}_{d}_{pk:g}.jpg",
            "status": "ok",
            "material": material,
            "actuator": a,
            "trial": "1",
            "direction": d,
            "pressure_kpa": pk,
            "l0_mm": l0_mm,
            "psi_deg": 200.0 - 10.0 * pk + psi_offset,
        }
        for a in ("A1", "A2")
        for d in ("up", "down")
        for pk in p
    ]
    return pd.DataFrame(rows)


def _hyst_of(angles: pd.DataFrame) -> pd.DataFrame:
    from pipeline.aggregate import aggregate_hysteresis

    return pd.concat(
        [aggregate_hysteresis(g).assign(dataset=d) for d, g in angles.groupby("dataset")],
        ignore_index=True,
    )


def test_each_dataset_is_compared_at_its_own_l0():
    """Datasets of one material pool only when they share l0; each row says which l0 and why."""
    angles = pd.concat(
        [
            _angles("a", "SS50", 255.0),
            _angles("b", "SS50", 220.0, psi_offset=5.0),
            _angles("c", "SS50", 255.0),
            _angles("d", "SS50", np.nan),
        ],
        ignore_index=True,
    )
    calls = []

    def model(material, p, l0_mm):
        calls.append(l0_mm)
        return 200.0 - 10.0 * np.asarray(p, float) + (5.0 if l0_mm == 220.0 else 0.0)

    out = compare(
        _hyst_of(angles),
        angles,
        model_psi=model,
        fit_k_p=None,
        default_l0_mm={"SS50": 250.0},
        data_sources={"a": "synthetic", "b": "measured", "c": "synthetic", "d": "measured"},
    )
    assert list(out["curve"]) == ["SS50, l0 250 mm", "SS50, l0 220 mm", "SS50, l0 255 mm"]
    rows = out.set_index("curve")
    assert rows.loc["SS50, l0 255 mm", "datasets"] == "a + c"
    assert rows.loc["SS50, l0 255 mm", "l0_source"] == "photo set"
    assert rows.loc["SS50, l0 255 mm", "rms_kind"] == "self-check"
    assert rows.loc["SS50, l0 220 mm", "rms_kind"] == "prediction"
    assert rows.loc["SS50, l0 250 mm", "datasets"] == "d"  # no l0 in its angles: the default
    assert rows.loc["SS50, l0 250 mm", "l0_source"] == "materials file"
    assert sorted(set(calls)) == [220.0, 250.0, 255.0]
    # every comparison meets its own model exactly (b's data are 5 deg up, so is its 220 mm model)
    np.testing.assert_allclose(out["rms_deg"], 0.0, atol=1e-12)
    assert (out["n_actuators"] == [2, 2, 4]).all()
    mixed = compare(
        _hyst_of(angles),
        angles,
        model_psi=model,
        fit_k_p=None,
        data_sources={"a": "synthetic", "b": "measured"},
    )
    assert "unknown" in set(mixed["rms_kind"])  # c and d have no stated source


def test_a_measured_set_never_pools_with_synthetic_ramps_of_the_same_material_and_l0():
    # a lab adds its own DS20 photos (l0 255 mm) beside the default synthetic DS20 ramps of the
    # same l0: it was one row "my_actuator + DS20", rms_kind mixed; its own RMS was not reported
    angles = pd.concat(
        [_angles("mine", "DS20", 255.0), _angles("DS20", "DS20", 255.0),
         _angles("more", "DS20", 255.0)],
        ignore_index=True,
    )
    out = compare(
        _hyst_of(angles),
        angles,
        model_psi=lambda m, p, l0: 200.0 - 10.0 * np.asarray(p, float),
        fit_k_p=None,
        data_sources={"mine": "measured", "DS20": "synthetic", "more": "measured"},
    )
    rows = out.set_index("curve")
    assert sorted(rows.index) == ["DS20, l0 255 mm, measured", "DS20, l0 255 mm, synthetic"]
    assert rows.loc["DS20, l0 255 mm, measured", "datasets"] == "mine + more"
    assert rows.loc["DS20, l0 255 mm, measured", "rms_kind"] == "prediction"
    assert rows.loc["DS20, l0 255 mm, synthetic", "rms_kind"] == "self-check"
    assert "mixed" not in set(out["rms_kind"])


def test_a_dataset_mixing_l0_keeps_its_data_figures_and_says_why_no_model():
    one = pd.concat(
        [_angles("x", "DS20", 200.0), _angles("x", "DS20", 220.0).assign(actuator="B1")],
        ignore_index=True,
    )
    with pytest.warns(UserWarning, match="several l0 .200, 220 mm"):
        out = compare(_hyst_of(one), one, model_psi=linear_model, fit_k_p=ls_fit).iloc[0]
    assert out["curve"] == "DS20, x (several l0)" and math.isnan(out["l0_mm"])
    assert math.isnan(out["rms_deg"]) and math.isnan(out["k_p_fit"]) and out["range_deg"] == 200.0
    assert "split the photo set into one dataset per l0" in out["note"]


def test_cli_curves_are_the_ones_each_rms_used(tmp_path, capsys):
    """compare --curves writes, per rms.csv row, the model curve at that row's l0 (real model)."""
    from pipeline import model
    from pipeline.cli import main

    folders = []
    for name, l0 in (("short", 220.0), ("long", None)):
        p = np.arange(0.0, 241.0, 40.0)
        psi = model.psi_deg("SS50", p, l0_mm=l0)
        rows = [
            {
                "image": f"{d}_{pk:g}.jpg",
                "psi_deg": s,
                "status": "ok",
                "reason": "",
                "pressure_kpa": pk,
                "direction": d,
                "material": "SS50",
                "actuator": "A1",
                "trial": 1,
                "l0_mm": l0,
            }
            for d in ("up", "down")
            for pk, s in zip(p, psi, strict=True)
        ]
        folder = tmp_path / name
        folder.mkdir()
        frame = pd.DataFrame(rows)
        if l0 is None:
            frame = frame.drop(columns="l0_mm")
        frame.to_csv(folder / "angles.csv", index=False)
        assert (
            main(["aggregate", str(folder / "angles.csv"), "--out", str(folder / "hysteresis.csv")])
            == 0
        )
        folders.append(folder)
    (folders[0] / "truth.csv").write_text("image,psi_deg\n")  # 'short' was rendered by synth
    rms, curves = tmp_path / "rms.csv", tmp_path / "curves.csv"
    assert (
        main(
            [
                "compare",
                *(str(f / "hysteresis.csv") for f in folders),
                "--angles",
                *(str(f / "angles.csv") for f in folders),
                "--photosets",
                *(str(f) for f in folders),
                "--bootstrap",
                "0",
                "--out",
                str(rms),
                "--curves",
                str(curves),
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert (
        "compare: SS50, l0 220 mm [short; l0 from photo set; materials packaged "
        "(pipeline/model/materials.yaml); self-check]"
    ) in text
    out = pd.read_csv(rms).set_index("datasets")
    default = model.load_materials()["SS50"].l0_mm
    assert out.loc["short", "l0_mm"] == 220.0 and out.loc["long", "l0_mm"] == default
    assert (
        out.loc["long", "l0_source"] == "materials file"
        and out.loc["long", "rms_kind"] == "prediction"
    )
    assert (out["rms_deg"] < 1e-3).all()  # each set was drawn from the model at its own l0
    c = pd.read_csv(curves)
    assert set(c["curve"]) == set(out["curve"])
    short = c[c["curve"] == "SS50, l0 220 mm"]
    assert (short["l0_mm"] == 220.0).all() and len(short) == 400
    expected = model.model_curve("SS50", l0_mm=220.0)
    np.testing.assert_allclose(
        short["pressure_kpa"], expected["pressure_kpa"], rtol=1e-5, atol=1e-9
    )
    assert not np.allclose(
        expected["pressure_kpa"], model.model_curve("SS50")["pressure_kpa"], rtol=1e-3
    )
    assert (
        main(
            [
                "compare",
                str(folders[0] / "hysteresis.csv"),
                "--photosets",
                "a",
                "b",
                "--out",
                str(rms),
            ]
        )
        == 2
    )


def test_a_dataset_with_its_own_materials_file_is_compared_against_that_files_model():
    """Own file: its callables, psi0 and l0; pooled only with datasets of the same file; named in
    each row."""
    from pipeline.compare import DatasetModel

    angles = pd.concat(
        [
            _angles("std", "SS50", np.nan),
            _angles("soft", "SS50", np.nan, psi_offset=7.0),
            _angles("soft2", "SS50", np.nan, psi_offset=7.0),
            _angles("short", "SS50", 220.0, psi_offset=7.0),
        ],
        ignore_index=True,
    )
    calls = []

    def own_model(material, p, l0_mm):
        calls.append(("own", l0_mm))
        return linear_model(material, p) + 7.0

    def run_model(material, p, l0_mm):
        calls.append(("run", l0_mm))
        return linear_model(material, p)

    soft = DatasetModel("lab/soft.yaml", own_model, ls_fit, {"SS50": 180.0}, {"SS50": 240.0})
    out = compare(
        _hyst_of(angles),
        angles,
        model_psi=run_model,
        fit_k_p=None,
        psi0_deg={"SS50": 210.0},
        default_l0_mm={"SS50": 255.0},
        materials_file="packaged",
        dataset_models={"soft": soft, "soft2": soft, "short": soft},
    )
    rows = out.set_index("curve")
    assert list(out["curve"]) == [
        "SS50, l0 255 mm",
        "SS50, l0 240 mm, materials lab/soft.yaml",
        "SS50, l0 220 mm, materials lab/soft.yaml",
    ]
    assert rows["datasets"].tolist() == ["std", "soft + soft2", "short"]
    assert rows["materials_file"].tolist() == ["packaged", "lab/soft.yaml", "lab/soft.yaml"]
    assert rows["l0_source"].tolist() == ["materials file", "dataset's materials file", "photo set"]
    assert rows["psi0_deg"].tolist() == [210.0, 180.0, 180.0]  # the file's geometry
    # each row met its own model exactly: std the run's, soft (+7 deg) its file's, at the file's or
    # photo set's l0
    np.testing.assert_allclose(out["rms_deg"], 0.0, atol=1e-12)
    assert sorted(set(calls)) == [("own", 220.0), ("own", 240.0), ("run", 255.0)]
    # without its own file the same data are 7 deg off the run's model
    just_soft = angles[angles["dataset"] == "soft"]
    plain = compare(
        _hyst_of(just_soft),
        just_soft,
        model_psi=run_model,
        fit_k_p=None,
        default_l0_mm={"SS50": 255.0},
    )
    assert plain["rms_deg"].tolist() == [pytest.approx(7.0)] and plain["curve"].tolist() == [
        "SS50, l0 255 mm"
    ]


def test_cli_compares_a_dataset_against_its_own_materials_file(tmp_path, capsys, soft_ss50):
    """compare --dataset-materials: the real model of the dataset's file (half SS50's modulus, l0
    240 mm)."""
    from pipeline import model
    from pipeline.cli import main

    own = tmp_path / "soft.yaml"
    own.write_text(soft_ss50)
    soft = model.load_materials(own)["SS50"]
    folders = []
    for name in ("std", "soft"):
        p = np.arange(0.0, 241.0, 40.0)
        psi = model.psi_deg("SS50", p)  # both drawn from the packaged SS50 at its l0
        rows = [
            {
                "image": f"{d}_{pk:g}.jpg",
                "psi_deg": s,
                "status": "ok",
                "reason": "",
                "pressure_kpa": pk,
                "direction": d,
                "material": "SS50",
                "actuator": "A1",
                "trial": 1,
            }
            for d in ("up", "down")
            for pk, s in zip(p, psi, strict=True)
        ]
        folder = tmp_path / name
        folder.mkdir()
        pd.DataFrame(rows).to_csv(folder / "angles.csv", index=False)
        assert (
            main(["aggregate", str(folder / "angles.csv"), "--out", str(folder / "hysteresis.csv")])
            == 0
        )
        folders.append(folder)
    rms, curves = tmp_path / "rms.csv", tmp_path / "curves.csv"
    args = [
        "compare",
        *(str(f / "hysteresis.csv") for f in folders),
        "--angles",
        *(str(f / "angles.csv") for f in folders),
        "--datasets",
        "std",
        "soft",
        "--bootstrap",
        "0",
        "--out",
        str(rms),
        "--curves",
        str(curves),
    ]
    assert main([*args, "--dataset-materials", "-", str(own)]) == 0
    assert f"materials {own}; " in capsys.readouterr().out
    out = pd.read_csv(rms).set_index("datasets")
    assert out.loc["std", "materials_file"] == "packaged (pipeline/model/materials.yaml)"
    assert out.loc["soft", "materials_file"] == str(own) and out.loc["soft", "l0_mm"] == 240.0
    assert out.loc["soft", "l0_source"] == "dataset's materials file"
    assert out.loc["std", "rms_deg"] < 1e-3  # drawn from the packaged model
    hyst = pd.read_csv(folders[1] / "hysteresis.csv")
    p, psi = hyst["pressure_kpa"].to_numpy(float), hyst["psi_mean_deg"].to_numpy(float)
    expected = rms_deg(psi, model.psi_deg(soft, p, l0_mm=240.0))[0]
    assert out.loc["soft", "rms_deg"] == pytest.approx(expected, rel=1e-4) and expected > 5.0
    c = pd.read_csv(curves)
    own_curve = c[c["curve"] == out.loc["soft", "curve"]]
    assert len(own_curve) == 400 and (own_curve["materials_file"] == str(own)).all()
    np.testing.assert_allclose(
        own_curve["pressure_kpa"],
        model.model_curve(soft, l0_mm=240.0)["pressure_kpa"],
        rtol=1e-5,
        atol=1e-9,
    )
    std_curve = c[c["curve"] == out.loc["std", "curve"]]
    assert not np.allclose(std_curve["pressure_kpa"], own_curve["pressure_kpa"], equal_nan=True)
    assert main([*args, "--dataset-materials", str(own)]) == 2  # one file per dataset, or '-'
