"""Force aggregation (pipeline.force.aggregate_force) on crafted data with hand-computed values,
and grasp-log validation/summary (pipeline.force.grasp)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pipeline.errors import UserInputError
from pipeline.force.aggregate_force import (
    eccentricity_at_max_pressure,
    force_vs_pressure,
    read_tables,
)
from pipeline.force.grasp import EXAMPLE_LOG, heaviest_held, read_grasp_log


def crafted() -> pd.DataFrame:
    """Two materials; DS20 at 0 and 100 kPa for 2 actuators x 2 trials, SS40 at 200 kPa once."""
    rows = [
        # material, pressure, actuator, trial, force_n, force_sd_n, e, status
        ("DS20", 0.0, "A1", "1", 0.0, 0.01, 0.05, "flagged"),
        ("DS20", 0.0, "A1", "2", 0.1, 0.03, 0.07, "flagged"),
        ("DS20", 0.0, "A2", "1", 0.2, 0.00, 0.06, "flagged"),
        ("DS20", 0.0, "A2", "2", 0.1, 0.04, 0.08, "flagged"),
        ("DS20", 100.0, "A1", "1", 2.0, 0.10, 0.60, "ok"),
        ("DS20", 100.0, "A1", "2", 3.0, 0.20, 0.62, "ok"),
        ("DS20", 100.0, "A2", "1", 2.5, 0.20, 0.58, "ok"),
        ("DS20", 100.0, "A2", "2", 3.5, 0.10, 0.90, "flagged"),
        ("SS40", 200.0, "B1", "1", 5.0, 0.05, 0.55, "ok"),
    ]
    df = pd.DataFrame(
        rows,
        columns=[
            "material",
            "pressure_kpa",
            "actuator",
            "trial",
            "force_n",
            "force_sd_n",
            "eccentricity",
            "status",
        ],
    )
    df["direction"] = "up"
    df["measured_pressure_kpa"] = df["pressure_kpa"] + 0.5
    df["image"] = [f"img{i}.jpg" for i in range(len(df))]
    df["image_path"] = "/x/" + df["image"]
    for k, v in {
        "centre_x_px": 10.0,
        "centre_y_px": 20.0,
        "semi_major_px": 30.0,
        "semi_minor_px": 25.0,
        "angle_deg": 5.0,
    }.items():
        df[k] = v
    return df


def test_force_mean_and_sd_by_hand() -> None:
    s = force_vs_pressure(crafted()).set_index(["material", "pressure_kpa"])
    row = s.loc[("DS20", 100.0)]
    # forces 2.0, 3.0, 2.5, 3.5: mean 2.75, sample variance ((.75^2+.25^2)*2)/3 = 1.25/3
    assert row["force_mean_n"] == pytest.approx(2.75)
    assert row["force_sd_n"] == pytest.approx(np.sqrt(1.25 / 3))
    assert row["n"] == 4 and row["n_actuators"] == 2 and row["n_trials"] == 4
    # pooled load-cell spread sqrt(mean(.01, .04, .04, .01)) = sqrt(0.025)
    assert row["sample_sd_n"] == pytest.approx(np.sqrt(0.025))
    assert row["measured_pressure_mean_kpa"] == pytest.approx(100.5)
    # eccentricity uses ok photos only: 0.60, 0.62, 0.58 -> mean 0.6, sd 0.02
    assert row["eccentricity_mean"] == pytest.approx(0.6)
    assert row["eccentricity_sd"] == pytest.approx(0.02)
    assert row["n_eccentricity"] == 3
    low = s.loc[("DS20", 0.0)]
    assert low["force_mean_n"] == pytest.approx(0.1)
    assert low["force_sd_n"] == pytest.approx(np.sqrt(0.02 / 3))
    assert low["n_eccentricity"] == 0 and np.isnan(low["eccentricity_mean"])
    single = s.loc[("SS40", 200.0)]
    assert single["force_mean_n"] == 5.0 and np.isnan(single["force_sd_n"])


def test_rows_without_force_are_ignored_and_directions_kept_apart() -> None:
    df = crafted()
    extra = df.iloc[[4]].copy()
    extra["direction"] = "down"
    extra["force_n"] = 9.0
    nan_row = df.iloc[[5]].copy()
    nan_row["force_n"] = np.nan
    s = force_vs_pressure(pd.concat([df, extra, nan_row], ignore_index=True))
    up = s[(s.material == "DS20") & (s.pressure_kpa == 100.0) & (s.direction == "up")].iloc[0]
    down = s[(s.direction == "down")].iloc[0]
    assert up["n"] == 4 and up["force_mean_n"] == pytest.approx(2.75)
    assert down["n"] == 1 and down["force_mean_n"] == 9.0


def test_eccentricity_at_max_pressure_by_hand() -> None:
    e = eccentricity_at_max_pressure(crafted()).set_index("material")
    ds20 = e.loc["DS20"]
    assert ds20["pressure_kpa"] == 100.0
    assert ds20["eccentricity_mean"] == pytest.approx(0.6)
    assert ds20["eccentricity_sd"] == pytest.approx(0.02)
    assert ds20["n"] == 3 and ds20["n_excluded"] == 1
    assert ds20["force_mean_n"] == pytest.approx(2.75)
    assert ds20["image"] == "img4.jpg"  # e = 0.60 is closest to the mean
    assert ds20["semi_major_px"] == 30.0
    assert e.loc["SS40", "eccentricity_mean"] == pytest.approx(0.55)


def test_read_tables_checks_columns(tmp_path: Path) -> None:
    good = tmp_path / "e.csv"
    crafted().to_csv(good, index=False)
    assert len(read_tables([good, good])) == 18
    bad = tmp_path / "bad.csv"
    crafted().drop(columns=["force_n"]).to_csv(bad, index=False)
    with pytest.raises(UserInputError, match=r"bad.csv.*force_n"):
        read_tables([bad])
    with pytest.raises(UserInputError, match="not found"):
        read_tables([tmp_path / "none.csv"])


# ----------------------------------------------------------------------------- grasp log


def test_example_grasp_log_matches_the_paper_text() -> None:
    s = heaviest_held(read_grasp_log(EXAMPLE_LOG))
    ring = s[(s.side == "inside") & (s.diameter_mm == 90)].set_index(["material", "pressure_kpa"])
    for material in ("DS20", "DS30", "SS40"):
        for p in (0.0, 20.0, 40.0, 60.0):
            assert ring.loc[(material, p), "max_mass_held_g"] == 700
    assert np.isnan(ring.loc[("DS20", 80.0), "max_mass_held_g"])  # buckled
    assert ring.loc[("DS30", 80.0), "max_mass_held_g"] == 750
    assert ring.loc[("SS40", 80.0), "max_mass_held_g"] == 800
    assert ring.loc[("SS50", 20.0), "max_mass_held_g"] == 1000


def test_heaviest_held_takes_the_max_of_held_rows(tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    log.write_text(
        "material,object,side,diameter_mm,mass_g,pressure_kpa,held,comment\n"
        "DS30,cup,inside,90,300,40,yes,\n"
        "DS30,cup+weights,inside,90,650,40,TRUE,\n"
        "DS30,cup+more,inside,90,900,40,no,slipped\n"
        "DS30,cup,Inside,90,300,60,0,\n"
    )
    s = heaviest_held(read_grasp_log(log)).set_index("pressure_kpa")
    assert s.loc[40.0, "max_mass_held_g"] == 650
    assert s.loc[40.0, "n_attempts"] == 3 and s.loc[40.0, "n_held"] == 2
    assert np.isnan(s.loc[60.0, "max_mass_held_g"])


def test_bad_grasp_rows_are_all_reported(tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    log.write_text(
        "material,object,side,diameter_mm,mass_g,pressure_kpa,held\n"
        "DS20,ring,inside,90,700,20,yes\n"
        "DS20,ring,between,90,700,20,yes\n"
        "DS20,ring,inside,ninety,700,20,maybe\n"
        ",ring,outside,90,-5,20,no\n"
    )
    with pytest.raises(UserInputError) as info:
        read_grasp_log(log)
    msg = str(info.value)
    assert "log.csv line 3, column side" in msg
    assert "line 4, column diameter_mm" in msg and "line 4, column held" in msg
    assert "line 5, column material" in msg and "line 5, column mass_g" in msg
    assert "4 problem" not in msg and "5 problem(s)" in msg


def test_grasp_log_missing_column(tmp_path: Path) -> None:
    log = tmp_path / "log.csv"
    log.write_text("material,object,diameter_mm,mass_g,pressure_kpa,held\nDS20,x,90,1,1,yes\n")
    with pytest.raises(UserInputError, match=r"missing column\(s\) \['side'\]"):
        read_grasp_log(log)


def test_manifest_without_eccentricity_gives_force_only(tmp_path: Path) -> None:
    manifest = crafted().drop(columns=["eccentricity", "status"])
    path = tmp_path / "manifest.csv"
    manifest.to_csv(path, index=False)
    table = read_tables([path])
    force = force_vs_pressure(table)
    assert force["n_eccentricity"].eq(0).all() and force["eccentricity_mean"].isna().all()
    assert force.set_index(["material", "pressure_kpa"]).loc[
        ("DS20", 100.0), "force_mean_n"
    ] == pytest.approx(2.75)
    assert eccentricity_at_max_pressure(table).empty
