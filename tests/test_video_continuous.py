"""Continuous aggregation: step-response figures against closed forms and the video's truth,
loops."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from pipeline.aggregate import aggregate_hysteresis
from pipeline.errors import UserInputError
from pipeline.synth.video import Dynamics, simulate, toy_actuator
from pipeline.video import continuous
from pipeline.video.continuous import UNSETTLED, loops, step_response, steps, write_continuous
from pipeline.video.profile import PressureProfile

T = np.arange(0.0, 6.0, 0.01)


def _first_order(tau: float) -> np.ndarray:
    return 50.0 + 30.0 * (1 - np.exp(-(T - 1.0) / tau)) * (T >= 1.0)


def test_a_step_is_from_the_level_held_before_it_and_its_way_is_its_own():
    # customer 15: a 20 Hz log of setpoints and 30 fps frames; a frame between the two log lines
    # across a jump read 13.3 kPa, which steps.csv gave as the level the step came from, and the
    # step up to the top level was "down" (its hold's last frame already counted the fall)
    from pipeline.video.timeline import PressureLog, frame_conditions

    levels = [0, 40, 80, 40, 0]
    t_log = np.arange(0.0, 7.5, 0.05)
    log = PressureLog("log.csv", t_log, np.array([levels[min(int(t // 1.5), 4)] for t in t_log],
                                                 float))
    t = np.arange(0.0, 7.4, 1.0 / 30.0) + 0.02
    frames = frame_conditions(log, t).assign(
        image="v.avi", frame=np.arange(len(t)), time_s=t, psi_deg=100.0 - t, status="ok",
        material="DS30",
        actuator="A1", trial=1,
    )
    # frames between the log lines across a jump keep the level in force (customer 27)
    assert frames["pressure_kpa"].isin(levels).all()
    got, _ = steps(frames)
    assert list(got["from_kpa"]) == [0, 40, 80, 40] and list(got["to_kpa"]) == [40, 80, 40, 0]
    assert list(got["direction"]) == ["up", "up", "down", "down"]


def test_first_order_step_gives_its_closed_form_times():
    r = step_response(T, _first_order(0.3), step_time_s=1.0, before_deg=50.0)
    assert r["rise_time_s"] == pytest.approx(0.3 * np.log(9), abs=0.01)
    assert r["settling_time_s"] == pytest.approx(0.3 * np.log(50), abs=0.02)
    assert (
        r["overshoot_pct"] == 0.0
        and r["note"] == ""
        and r["change"] == pytest.approx(30.0, abs=0.01)
    )


def test_a_hold_whose_last_frames_are_flagged_has_no_final_value():
    # a customer's step down to 40 kPa: the tip left the photo once the actuator straightened,
    # so the hold's last frames were flagged, and its "final value" came from the frames on the
    # way there (a change of 66 deg where it was about 124); flagged frames come as NaN
    psi = _first_order(0.3)
    late = psi.copy()
    late[T > 4.0] = np.nan  # the last third of the hold not used
    r = step_response(T, late, step_time_s=1.0, before_deg=50.0)
    assert math.isnan(r["change"])
    assert "of the hold's last" in r["note"] and "no final value" in r["note"]
    # one flagged frame at the end leaves the rest of the end to give it
    one = psi.copy()
    one[-1] = np.nan
    r = step_response(T, one, step_time_s=1.0, before_deg=50.0)
    assert r["change"] == pytest.approx(30.0, abs=0.01) and r["note"] == ""


def test_underdamped_step_gives_its_overshoot_and_settling():
    zeta, wn = 0.3, 8.0
    wd = wn * np.sqrt(1 - zeta**2)
    u = np.clip(T - 1.0, 0, None)
    y = 10.0 - 20.0 * (
        1 - np.exp(-zeta * wn * u) * (np.cos(wd * u) + zeta / np.sqrt(1 - zeta**2) * np.sin(wd * u))
    )
    r = step_response(T, y, step_time_s=1.0, before_deg=10.0)
    assert r["overshoot_pct"] == pytest.approx(
        100 * np.exp(-zeta * np.pi / np.sqrt(1 - zeta**2)), abs=0.5
    )
    outside = np.flatnonzero(np.abs(y - (-10.0)) > 0.02 * 20.0)
    assert r["settling_time_s"] == pytest.approx(T[outside[-1] + 1] - 1.0, abs=0.02)


def test_a_hold_too_short_or_a_change_too_small_has_no_figures():
    # 2.4 tau
    short = step_response(T[T < 2.2], _first_order(0.5)[T < 2.2], step_time_s=1.0, before_deg=50.0)
    assert short["note"] == "did not settle within the hold"
    assert (
        np.isnan(short["settling_time_s"])
        and np.isnan(short["rise_time_s"])
        and np.isnan(short["overshoot_pct"])
    )
    flat = step_response(T, np.full_like(T, 50.0) + 0.3 * (T > 1), step_time_s=1.0, before_deg=50.0)
    assert "too small" in flat["note"] and np.isnan(flat["rise_time_s"])


def test_steps_measured_on_the_video_match_the_steps_of_its_truth(video_set, measured):
    truth = pd.read_csv(video_set / "truth.csv")
    ideal = measured.drop(columns="psi_deg").merge(
        truth[["image", "frame", "psi_image_deg"]], on=["image", "frame"]
    )
    ideal = ideal.rename(columns={"psi_image_deg": "psi_deg"}).assign(status="ok")
    got, curves = steps(measured)
    want, _ = steps(ideal)
    assert list(got["step"]) == [1, 2, 3, 4] and list(got["direction"]) == [
        "up",
        "up",
        "down",
        "down",
    ]
    assert np.allclose(got["time_s"], [1.2 + 2.5 * k for k in range(1, 5)], atol=1e-6)
    assert list(got["to_kpa"]) == [40, 80, 40, 0] and list(got["from_kpa"]) == [0, 40, 80, 40]
    assert np.allclose(got["psi_final_deg"], want["psi_final_deg"], atol=0.2)
    assert np.allclose(got["rise_time_s"], want["rise_time_s"], atol=0.1)  # one frame period
    # the closed form: the actuator's 0.4 s lag behind the regulator's 0.15 s lag (simulated finely)
    sim = simulate(
        PressureProfile("steps", max_kpa=40, step_kpa=40, hold_s=2.5),
        toy_actuator(),
        Dynamics(),
        start_s=0.0,
        end_s=5.0,
    )
    hold = sim[sim["time_s"] >= 2.5]
    exact = step_response(
        hold["time_s"].to_numpy(), hold["psi_deg"].to_numpy(), step_time_s=2.5, before_deg=210.0
    )
    assert np.allclose(got["rise_time_s"], exact["rise_time_s"], atol=0.1)
    assert np.allclose(got["pressure_rise_time_s"], 0.15 * np.log(9), atol=0.1)
    assert (got["change_deg"].iloc[:2] < -10).all() and (got["change_deg"].iloc[2:] > 10).all()
    assert set(curves["step"]) == {1, 2, 3, 4}
    start = curves.sort_values("since_step_s").groupby("step").first()
    assert (start["response"].abs() < 0.1).all() and (
        curves.groupby("step")["response"].max() > 0.9
    ).all()


def test_loops_and_cycles_of_the_video(measured):
    # as the frames of a continuous ramp (no steps in the log): every frame is binned
    ramped = measured.assign(since_step_s=np.nan)
    binned, cycles = loops(ramped, bin_kpa=10)
    assert set(binned["direction"]) == {"up", "down"} and (binned["cycle"] == 1).all()
    assert binned.groupby("direction")["n"].sum().sum() == (measured["status"] == "ok").sum()
    assert len(cycles) == 1 and cycles["bins_compared"].iloc[0] >= 3
    # mean setpoint rate over each leg while the pressure moves: 80 kPa from the last frame at
    # rest (1.1 s) to the first at the top (3.7 s); the rest before the steps and the top hold are
    # not counted (customer 20's 8 kPa/s ramp read 7.6 with its 1.5 s at rest)
    assert cycles["rate_up_kpa_s"].iloc[0] == pytest.approx(80 / (3.7 - 1.1), rel=0.02)
    with pytest.raises(UserInputError, match="positive"):
        loops(measured, bin_kpa=0)
    # the video as it is, stepped through held pressures: only the ends of its holds, at the
    # levels it held (the frames between are the steps' response, not hysteresis)
    held, held_cycles = loops(measured, bin_kpa=10)
    assert set(held["pressure_kpa"]) == {0.0, 40.0, 80.0} and held["n"].sum() < 60
    assert held_cycles["bins_compared"].iloc[0] == 2  # 0 and 40 kPa, both ways
    assert held_cycles["rate_up_kpa_s"].iloc[0] == cycles["rate_up_kpa_s"].iloc[0]


def test_hysteresis_of_frames_is_binned_and_a_video_trial_counts_once_per_level(measured):
    # of a stepped video, the ends of its holds only: the levels it held
    held = aggregate_hysteresis(measured)
    assert sorted(map(tuple, held[["direction", "pressure_kpa"]].to_numpy().tolist())) == [
        ("down", 0.0), ("down", 40.0), ("up", 0.0), ("up", 40.0), ("up", 80.0)
    ]
    assert (held["n"] == 1).all()
    # as the frames of a continuous ramp (no steps in the log): binned by measured pressure
    measured = measured.assign(since_step_s=np.nan)
    h = aggregate_hysteresis(measured)
    assert len(h) < 40 and np.allclose(h["pressure_kpa"] % continuous.BIN_KPA, 0)
    # one trial: one value per bin, sd undefined
    assert (h["n"] == 1).all() and (h["n_trials"] == 1).all()
    two = pd.concat(
        [measured, measured.assign(trial="2", psi_deg=measured["psi_deg"] + 1.0)], ignore_index=True
    )
    h2 = aggregate_hysteresis(two)
    # values x and x + 1
    assert (h2["n"] == 2).all() and np.allclose(h2["psi_sd_deg"], np.sqrt(0.5))
    level = h[(h["direction"] == "up") & (h["pressure_kpa"] == 40)]
    frames = measured[
        (measured["direction"] == "up")
        & ((measured["measured_pressure_kpa"] / 5).round() == 8)
        & (measured["status"] == "ok")
    ]
    assert np.isclose(level["psi_mean_deg"].iloc[0], frames["psi_deg"].mean())


def test_cli_writes_every_table_and_refuses_photos(measured, tmp_path):
    path = tmp_path / "angles.csv"
    measured.to_csv(path, index=False)
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "pipeline",
            "continuous",
            str(path),
            "--out-dir",
            str(tmp_path / "c"),
        ],
        capture_output=True,
        text=True, check=False,
    )
    assert out.returncode == 0, out.stderr
    assert "1 cycle(s), 4 step(s)" in out.stdout
    for name in continuous.FILES:
        assert (tmp_path / "c" / name).is_file()
    measured.drop(columns=["frame"]).to_csv(path, index=False)
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "pipeline",
            "continuous",
            str(path),
            "--out-dir",
            str(tmp_path / "d"),
        ],
        capture_output=True,
        text=True, check=False,
    )
    assert out.returncode == 2 and "needs the frames of a video" in out.stderr


def test_tables_are_deterministic(measured, tmp_path):
    write_continuous(measured, tmp_path / "a")
    write_continuous(measured, tmp_path / "b")
    for name in continuous.FILES:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


def test_one_frame_off_in_the_hold_is_the_measurements_not_an_unsettled_step():
    # customer 35's 80 -> 40 kPa step: one frame of the still actuator read 2.1 deg off the
    # hold's mean (the others within 1.5) and the step "did not settle within the hold"
    psi = _first_order(0.3) + np.random.default_rng(3).normal(0.0, 0.1, T.size)
    late = int(np.searchsorted(T, 5.5))  # in the hold's last fifth, its final value
    once = psi.copy()
    once[late] += 2.0
    r = step_response(T, once, step_time_s=1.0, before_deg=50.0)
    assert r["note"] == "" and r["settling_time_s"] == pytest.approx(0.3 * np.log(50), abs=0.1)
    # two frames in a row that far off are the actuator's (ringing): not settled
    psi[late : late + 2] += 2.0
    assert step_response(T, psi, step_time_s=1.0, before_deg=50.0)["note"] == UNSETTLED


def test_ringing_filmed_two_frames_a_lobe_still_counts_against_settling():
    # review: with a lone frame off the band forgiven, ringing at 7 Hz filmed at 30 fps (lobes of
    # two frames) must still hold the settling time back until it dies out
    t = np.arange(0.0, 6.0, 1.0 / 30.0)
    u = np.clip(t - 1.0, 0.0, None)
    y = 50.0 * (t >= 1.0) + 3.0 * np.exp(-u / 0.3) * np.sin(2 * np.pi * 7.0 * u) * (t >= 1.0)
    r = step_response(t, y, step_time_s=1.0, before_deg=0.0)
    outside = np.flatnonzero(np.abs(y - 50.0) > 0.02 * 50.0)
    assert r["settling_time_s"] >= t[outside[-1]] - 1.0 - 1.0 / 30.0, r



def test_a_hold_still_swinging_has_not_settled_however_wide_it_swings():
    # the band that follows the hold's own scatter (a still actuator's noise) must not take in a
    # swing that runs on through the hold: 1.5 deg at 2 Hz after a 50 deg step (3 % of it)
    t = np.arange(0.0, 6.0, 1.0 / 30.0)
    y = 50.0 * (t >= 1.0) + 1.5 * np.sin(2 * np.pi * 2.0 * (t - 1.0)) * (t >= 1.0)
    assert step_response(t, y, step_time_s=1.0, before_deg=0.0)["note"] == UNSETTLED
