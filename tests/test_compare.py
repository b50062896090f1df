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
    rows = [("up", 0, 200.0), ("up", 10, 100.0), ("up", 20, -50.0),
            ("down", 0, 190.0), ("down", 10, 20.0), ("down", 20, -50.0)]
    return pd.DataFrame([{"material": "DS20", "direction": d, "pressure_kpa": p, "psi_mean_deg": s,
                          "psi_sd_deg": 1.0, "n": 3, "n_actuators": 3, "n_trials": 3, "n_excluded": 0}
                         for d, p, s in rows])


def linear_model(material: str, pressure_kpa: np.ndarray) -> np.ndarray:
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
    def partial(material, p):
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
    assert (out["range_deg"], out["psi_max_deg"], out["psi_min_deg"], out["range_kpa"]) == (250.0, 200.0, -50.0, 20.0)
    assert hysteresis_width(_hyst()) == (80.0, 10.0)
    up_only = _hyst()[_hyst()["direction"] == "up"]
    w, at = hysteresis_width(up_only)
    assert math.isnan(w) and math.isnan(at)
    out = compare(up_only, model_psi=linear_model, fit_k_p=None).iloc[0]
    assert math.isnan(out["rms_down_deg"]) and math.isnan(out["p_zero_down_kpa"])
    assert out["rms_deg"] == pytest.approx(out["rms_up_deg"])


def _g(psi):
    return (200.0 - np.asarray(psi, float)) / 10.0


def ls_fit(material, p, psi):
    """k minimising sum (P - k g(psi))^2, a stand-in for the model's fit."""
    g = _g(psi)
    return float(g @ p / (g @ g)), None


def _rows(k_by_actuator):
    psi = np.array([200.0, 150.0, 100.0, 50.0, 0.0, -50.0])
    return pd.concat([pd.DataFrame({"actuator": a, "pressure_kpa": k * _g(psi), "psi_deg": psi})
                      for a, k in k_by_actuator.items()], ignore_index=True)


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
    out = compare(_hyst(), angles, model_psi=linear_model, fit_k_p=ls_fit, n_boot=20, seed=1).iloc[0]
    assert out["k_p_fit"] == pytest.approx(2.0)
    assert out["k_p_ci_low"] == pytest.approx(2.0) and out["k_p_ci_high"] == pytest.approx(2.0)
    assert out["n_actuators"] == 2


def test_unknown_material_keeps_data_metrics():
    def model(material, p):
        raise UserInputError(f"no material {material!r}")

    h = _hyst().assign(material="EcoFlex")
    with pytest.warns(UserWarning, match="EcoFlex"):
        out = compare(h, model_psi=model, fit_k_p=None).iloc[0]
    assert math.isnan(out["rms_deg"]) and out["range_deg"] == 250.0 and math.isnan(out["paper_rms_deg"])


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
                    rows.append({"image": f"{actuator}_{trial}_{direction}_{pk:g}.jpg", "psi_deg": psi,
                                 "status": "ok", "reason": "", "pressure_kpa": pk, "direction": direction,
                                 "material": "SS40", "actuator": actuator, "trial": trial})
    angles = tmp_path / "angles.csv"
    pd.DataFrame(rows).to_csv(angles, index=False)
    hyst, rms = tmp_path / "h.csv", tmp_path / "rms.csv"
    assert main(["aggregate", str(angles), "--out", str(hyst)]) == 0
    assert main(["compare", str(hyst), "--angles", str(angles), "--out", str(rms), "--seed", "3"]) == 0
    assert "SS40 RMS" in capsys.readouterr().out
    out = pd.read_csv(rms).iloc[0]
    finite = np.isfinite(truth)
    assert out["n_model_nan"] == 2 * int((~finite).sum())
    assert out["rms_deg"] < 2.0  # mean of 6 draws of sd 2 deg
    assert out["k_p_ci_low"] <= out["k_p_fit"] <= out["k_p_ci_high"]
    assert abs(out["k_p_fit"] - 2.2) < 0.1
    assert out["p_zero_up_kpa"] == pytest.approx(crossing_kpa(p, truth, 0.0), abs=3.0)
    assert main(["compare", str(tmp_path / "missing.csv"), "--out", str(rms)]) == 2
    # another reading of the model reaches the comparison: the printed l0 factor (l0 in metres)
    # is 16 % softer, so data drawn from the calibrated model need a larger k_P
    other = tmp_path / "rms_metres.csv"
    assert main(["compare", str(hyst), "--angles", str(angles), "--out", str(other), "--seed", "3",
                 "--l0-factor", "metres"]) == 0
    metres = pd.read_csv(other).iloc[0]
    assert metres["k_p_fit"] > out["k_p_fit"] * 1.1 and metres["rms_deg"] > out["rms_deg"]
    assert main(["compare", str(hyst), "--out", str(other), "--eq12-scale", "-1"]) == 2
