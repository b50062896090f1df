"""Aggregation of angles.csv into hysteresis curves, checked against hand-computed values."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from pipeline.aggregate import (
    HYSTERESIS_COLUMNS,
    aggregate_hysteresis,
    aggregate_per_actuator,
    pool_hysteresis,
    pressure_levels,
    read_angles,
)
from pipeline.cli import main
from pipeline.errors import UserInputError

COLUMNS = [
    "image",
    "psi_deg",
    "kappa_per_mm",
    "length_mm",
    "method",
    "residual_px",
    "status",
    "reason",
    "seconds",
    "pressure_kpa",
    "direction",
    "material",
    "actuator",
    "trial",
    "step",
]


def _row(psi, status, p, direction, actuator, trial, material="DS20", reason=""):
    return {
        "image": f"{material}_{actuator}_{trial}_{direction}_{p}.jpg",
        "psi_deg": psi,
        "kappa_per_mm": 0.0,
        "length_mm": 195.0,
        "method": "paper",
        "residual_px": 0.5,
        "status": status,
        "reason": reason,
        "seconds": 0.01,
        "pressure_kpa": p,
        "direction": direction,
        "material": material,
        "actuator": actuator,
        "trial": trial,
        "step": 0,
    }


@pytest.fixture()
def crafted() -> pd.DataFrame:
    rows = [
        # up, 0 kPa: 200, 210, 220 ok (mean 210, sd 10); one flagged 999
        _row(200.0, "ok", 0, "up", 1, 1),
        _row(210.0, "ok", 0, "up", 1, 2),
        _row(220.0, "ok", 0, "up", 2, 1),
        _row(999.0, "flagged", 0, "up", 2, 2, reason="short line"),
        # up, 10 kPa: 100, 120 ok (mean 110, sd sqrt(200)); one failed
        _row(100.0, "ok", 10, "up", 1, 1),
        _row(math.nan, "failed", 10, "up", 1, 2, reason="no line"),
        _row(120.0, "ok", 10, "up", 2, 1),
        # down, 10 kPa: a single value (sd undefined)
        _row(50.0, "ok", 10, "down", 1, 1),
        # down, 0 kPa: everything failed
        _row(math.nan, "failed", 0, "down", 1, 1, reason="no line"),
        # a second material, listed first to check the sorting
        _row(-5.0, "ok", 0, "up", "A", 1, material="SS50"),
    ]
    return pd.DataFrame(rows, columns=COLUMNS)


def _level(h, material, direction, p):
    sel = h[(h["material"] == material) & (h["direction"] == direction) & (h["pressure_kpa"] == p)]
    assert len(sel) == 1
    return sel.iloc[0]


def test_means_sds_and_counts(crafted):
    h = aggregate_hysteresis(crafted)
    assert list(h.columns) == list(HYSTERESIS_COLUMNS)
    assert list(zip(h["material"], h["direction"], h["pressure_kpa"])) == [
        ("DS20", "up", 0),
        ("DS20", "up", 10),
        ("DS20", "down", 0),
        ("DS20", "down", 10),
        ("SS50", "up", 0),
    ]
    r = _level(h, "DS20", "up", 0)
    assert r["psi_mean_deg"] == pytest.approx(210.0)
    assert r["psi_sd_deg"] == pytest.approx(10.0)
    assert (r["n"], r["n_actuators"], r["n_trials"], r["n_excluded"]) == (3, 2, 3, 1)
    r = _level(h, "DS20", "up", 10)
    assert r["psi_mean_deg"] == pytest.approx(110.0)
    assert r["psi_sd_deg"] == pytest.approx(math.sqrt(200.0))
    assert (r["n"], r["n_actuators"], r["n_trials"], r["n_excluded"]) == (2, 2, 2, 1)
    r = _level(h, "DS20", "down", 10)
    assert r["psi_mean_deg"] == 50.0 and math.isnan(r["psi_sd_deg"]) and r["n"] == 1
    r = _level(h, "DS20", "down", 0)  # kept, so the exclusions stay visible
    assert r["n"] == 0 and r["n_excluded"] == 1 and math.isnan(r["psi_mean_deg"])
    assert int(h["n"].sum()) + int(h["n_excluded"].sum()) == len(crafted)


def test_include_flagged(crafted):
    h = aggregate_hysteresis(crafted, include_flagged=True)
    r = _level(h, "DS20", "up", 0)
    values = np.array([200.0, 210.0, 220.0, 999.0])
    assert r["psi_mean_deg"] == pytest.approx(values.mean())
    assert r["psi_sd_deg"] == pytest.approx(values.std(ddof=1))
    assert (r["n"], r["n_excluded"]) == (4, 0)
    # failed rows stay excluded even then
    assert _level(h, "DS20", "up", 10)["n_excluded"] == 1


def test_per_actuator(crafted):
    per = aggregate_per_actuator(crafted)
    a1 = per[(per["material"] == "DS20") & (per["actuator"] == "1") & (per["direction"] == "up")]
    assert a1["pressure_kpa"].tolist() == [0, 10]
    assert a1["psi_mean_deg"].tolist() == pytest.approx([205.0, 100.0])
    assert a1["psi_sd_deg"].iloc[0] == pytest.approx(math.sqrt(50.0))
    assert a1["n_excluded"].tolist() == [0, 1]


def test_binning_uses_measured_pressure():
    df = pd.DataFrame(
        {
            "pressure_kpa": [10.0, 10.0, 10.0, 20.0],
            "measured_pressure_kpa": [8.1, 12.6, np.nan, 17.4],
        }
    )
    assert pressure_levels(df, 5.0).tolist() == [10.0, 15.0, 10.0, 15.0]
    assert pressure_levels(df).tolist() == [10.0, 10.0, 10.0, 20.0]
    rows = [
        _row(v, "ok", p, "up", 1, i)
        for i, (v, p) in enumerate([(10.0, 10), (20.0, 10), (30.0, 20)])
    ]
    angles = pd.DataFrame(rows, columns=COLUMNS)
    angles["measured_pressure_kpa"] = [9.0, 13.0, 16.0]
    h = aggregate_hysteresis(angles, bin_kpa=5.0)
    assert h["pressure_kpa"].tolist() == [10.0, 15.0]
    assert h["psi_mean_deg"].tolist() == pytest.approx([10.0, 25.0])
    assert h["pressure_mean_kpa"].tolist() == pytest.approx([9.0, 14.5])
    with pytest.raises(UserInputError, match="bin-kpa"):
        aggregate_hysteresis(angles, bin_kpa=0.0)


def test_cli_roundtrip_and_bad_input(crafted, tmp_path, capsys):
    a = tmp_path / "angles.csv"
    crafted.to_csv(a, index=False)
    out, per = tmp_path / "h.csv", tmp_path / "per.csv"
    assert main(["aggregate", str(a), "--out", str(out), "--per-actuator-out", str(per)]) == 0
    assert "1 excluded" not in capsys.readouterr().out  # the summary counts all 3 exclusions
    h = pd.read_csv(out)
    assert _level(h, "DS20", "up", 0)["psi_sd_deg"] == pytest.approx(10.0)
    assert set(pd.read_csv(per)["actuator"].astype(str)) == {"1", "2", "A"}
    bad = crafted.copy()
    bad.loc[3, "direction"] = "sideways"
    bad.to_csv(a, index=False)
    with pytest.raises(UserInputError, match=r"angles.csv line 5: 'direction'"):
        read_angles([a])
    assert main(["aggregate", str(a), "--out", str(out)]) == 2
    crafted.drop(columns="status").to_csv(a, index=False)
    with pytest.raises(UserInputError, match="missing column"):
        read_angles([a])
    with pytest.raises(UserInputError, match="not found"):
        read_angles([tmp_path / "nope.csv"])


def test_pooling_two_datasets_equals_aggregating_their_union(crafted):
    a = crafted.assign(dataset="first")
    b = crafted.assign(dataset="second", psi_deg=crafted["psi_deg"] * 0.5 + 3.0)
    pooled = pool_hysteresis(pd.concat([aggregate_hysteresis(a), aggregate_hysteresis(b)]))
    union = aggregate_hysteresis(pd.concat([a, b], ignore_index=True))
    pd.testing.assert_frame_equal(pooled, union, check_dtype=False)
    r = _level(union, "DS20", "up", 0)
    assert r["n_actuators"] == 4  # "first/1", "first/2", "second/1", "second/2"
    values = np.r_[200.0, 210.0, 220.0, 103.0, 108.0, 113.0]
    assert r["psi_sd_deg"] == pytest.approx(values.std(ddof=1))


def test_a_level_photographed_twice_in_one_trial_counts_once_for_that_trial():
    """Customer 39 photographed 60 kPa twice in trial 2: the trial weighed double in the mean
    (n 3) and its repeat shrank the sd; a flagged repeat is still counted as excluded."""
    rows = pd.DataFrame(
        {
            "image": ["a", "b", "c", "d"],
            "psi_deg": [100.0, 104.0, 90.0, 150.0],
            "status": ["ok", "ok", "ok", "flagged"],
            "pressure_kpa": 60.0,
            "direction": "up",
            "material": "DS20",
            "actuator": "A1",
            "trial": [2, 2, 1, 2],
        }
    )
    h = aggregate_hysteresis(rows).iloc[0]
    assert h["psi_mean_deg"] == pytest.approx((102.0 + 90.0) / 2)
    assert h["psi_sd_deg"] == pytest.approx(np.std([102.0, 90.0], ddof=1))
    assert (h["n"], h["n_trials"], h["n_excluded"]) == (2, 2, 1)


def test_ramps_labelled_one_trial_are_not_merged_as_repeats():
    """Three 0 -> 40 -> 0 ramps all labelled trial 1 (review): their photos at one level are not
    next to each other, so each counts (n 3 at 40 kPa up, its sd over the three)."""
    psi = {0.0: 0.0, 20.0: 50.0, 40.0: 100.0}
    pressures = [0.0, 20.0, 40.0, 20.0, 0.0] * 3
    rows = pd.DataFrame(
        {
            "image": [f"p{i}" for i in range(15)],
            "psi_deg": [psi[p] + 10.0 * (i // 5) for i, p in enumerate(pressures)],
            "status": "ok",
            "pressure_kpa": pressures,
            "direction": ["up", "up", "up", "down", "down"] * 3,
            "material": "DS20",
            "actuator": "A1",
            "trial": 1,
            "step": range(15),
        }
    )
    top = aggregate_hysteresis(rows).set_index(["direction", "pressure_kpa"]).loc[("up", 40.0)]
    assert top["n"] == 3 and top["psi_sd_deg"] == pytest.approx(10.0)
