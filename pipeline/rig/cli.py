"""``python -m pipeline rig ACTION``: emulate the Pico, calibrate the regulator, read/calibrate the
load cell.

Actions
-------
``emulate``
    Serve the protocol on a pseudo-terminal; prints ``PORT <name>`` and serves until killed
    (SIGUSR1 presses the emergency stop, SIGUSR2 releases it).
``calibrate``
    Step the DAC through codes, read the achieved pressure (the regulator's monitor, or a CSV
    of reference-gauge readings), fit and write the calibration file.
``load``
    Tare, read, or set the scale of the HX711 load cell (``--known-n`` with a known weight hung).
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.errors import UserInputError
from pipeline.fileio import read_user_csv


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Sub-actions and their options."""
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    e = sub.add_parser(
        "emulate",
        help="serve the Pico protocol on a pseudo-terminal (prints its port) until killed",
    )
    e.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="fault injection, repeatable: drop-after=N (commands), estop-at-set=K (K-th SET), "
             "slow=S (s per reply), garbage-every=N (replies)",
    )
    e.add_argument(
        "--link",
        type=Path,
        help="also expose the port as this symlink (kept across dropped connections)",
    )
    e.add_argument("--seed", type=int, default=0, help="seed of the simulated noise (default 0)")
    e.add_argument(
        "--device-max-kpa",
        type=float,
        default=300.0,
        help="firmware limit: SET above it gets ERR LIMIT (kPa, default 300)",
    )
    e.add_argument(
        "--lag-s",
        type=float,
        default=0.0,
        help="first-order time constant of the simulated pressure (s, default 0)",
    )
    e.add_argument(
        "--gain",
        type=float,
        default=0.97,
        help="simulated regulator: achieved / nominal pressure (default 0.97)",
    )
    e.add_argument(
        "--offset-kpa",
        type=float,
        default=-1.5,
        help="simulated regulator offset (kPa, default -1.5)",
    )
    e.add_argument(
        "--protocol",
        choices=("full", "base"),
        default="full",
        help="full: every command of pipeline/rig/firmware; base: only ID, SET, GET, VENT and EVT "
             "ESTOP, "
        "ERR PARSE to the extensions (CFG, WDOG, load cell), like other firmware (default full)",
    )

    c = sub.add_parser(
        "calibrate",
        help="fit kPa <-> DAC code from the regulator monitor or reference readings; write the "
             "calibration file",
    )
    c.add_argument("--port", help="serial port of the Pico (not needed with --readings)")
    c.add_argument("--out", type=Path, required=True, help="calibration file to write (YAML)")
    c.add_argument(
        "--points-kpa",
        default="0,50,100,150,200,250",
        help="nominal pressures to visit, comma separated (kPa, default 0,50,100,150,200,250); two "
             "points give a two-point calibration",
    )
    c.add_argument(
        "--settle-s",
        type=float,
        default=2.0,
        help="wait at each point before reading (s, default 2)",
    )
    c.add_argument(
        "--samples", type=int, default=5, help="monitor readings averaged per point (default 5)"
    )
    c.add_argument(
        "--method",
        choices=("linear", "piecewise"),
        help="fit: linear least squares or piecewise-linear (default: linear for 2 points, "
             "piecewise for more)",
    )
    c.add_argument(
        "--readings",
        type=Path,
        help="CSV with columns dac_code, pressure_kpa (reference-gauge readings); fit these "
             "instead of using the port",
    )
    c.add_argument("--max-kpa", type=float, help="host-side limit stored in the file (kPa)")

    ld = sub.add_parser("load", help="load cell: tare, read, or set the scale from a known force")
    ld.add_argument("--port", required=True, help="serial port of the Pico")
    ld.add_argument(
        "--tare", action="store_true", help="zero the load cell first (nothing hanging on it)"
    )
    ld.add_argument(
        "--known-n",
        type=float,
        help="a known force now on the cell (N, e.g. 0.5 kg x 9.81 = 4.905): sets the scale "
             "(counts per newton)",
    )
    ld.add_argument("--samples", type=int, default=10, help="readings averaged (default 10)")
    ld.add_argument(
        "--calibration",
        type=Path,
        help="calibration file to store the scale in (load_counts_per_newton)",
    )


def run(args: argparse.Namespace) -> int:
    """Dispatch to the action."""
    return {"emulate": _emulate, "calibrate": _calibrate, "load": _load}[args.action](args)


def _emulate(args: argparse.Namespace) -> int:
    from pipeline.rig.emulator import Emulator, PlantParams, parse_faults
    from pipeline.rig.firmware import rigcore

    faults = parse_faults(args.fault)
    emu = Emulator(
        plant=PlantParams(gain=args.gain, offset_kpa=args.offset_kpa, lag_s=args.lag_s),
        faults=faults,
        seed=args.seed,
        cfg=rigcore.Config(max_kpa=args.device_max_kpa),
        link=args.link,
        protocol=args.protocol,
    )
    done = threading.Event()

    def on_signal(signum: int, frame: Any) -> None:
        if signum == signal.SIGUSR1:
            emu.press_estop()
        elif signum == signal.SIGUSR2:
            emu.release_estop()
        else:
            done.set()

    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGUSR1, signal.SIGUSR2):
        signal.signal(sig, on_signal)
    emu.start()
    print(f"PORT {emu.port}", flush=True)
    print(
        f"emulating {rigcore.NAME} {rigcore.VERSION} ({args.protocol} protocol) on "
        f"{emu.slave_name}; faults: {faults}; "
        "stop with Ctrl-C",
        file=sys.stderr,
        flush=True,
    )
    while not done.wait(0.2):
        # dropped without --link: port is gone
        if emu._thread is not None and not emu._thread.is_alive():
            print("emulator: connection dropped (fault drop-after); exiting", file=sys.stderr)
            break
    emu.stop()
    return 0


def _parse_points(text: str) -> list[float]:
    try:
        points = [float(v) for v in text.split(",") if v.strip()]
    except ValueError as exc:
        raise UserInputError(
            f"--points-kpa {text!r}: use comma-separated numbers, e.g. 0,100,200"
        ) from exc
    if len(points) < 2:
        raise UserInputError("--points-kpa needs at least two pressures")
    return points


def _calibrate(args: argparse.Namespace) -> int:
    from pipeline.rig.calibration import fit_calibration, write_calibration

    if args.readings is not None:
        try:
            df = read_user_csv(args.readings)
            codes, kpa = df["dac_code"].to_numpy(), df["pressure_kpa"].to_numpy()
        except (OSError, KeyError, pd.errors.ParserError) as exc:
            raise UserInputError(
                f"{args.readings}: needs columns dac_code, pressure_kpa ({exc})"
            ) from exc
        cal = fit_calibration(
            codes, kpa, args.method, max_kpa=args.max_kpa, device="reference readings"
        )
    else:
        if not args.port:
            raise UserInputError("rig calibrate needs --port (or --readings CSV)")
        from pipeline.rig.driver import PicoDriver

        points = _parse_points(args.points_kpa)
        with PicoDriver.open(args.port, max_kpa=max(points)) as rig:
            cal = run_calibration(
                rig,
                points,
                settle_s=args.settle_s,
                samples=args.samples,
                method=args.method,
                max_kpa=args.max_kpa,
            )
    write_calibration(args.out, cal)
    print(f"calibration ({cal.method}, {len(cal.dac_code)} points) written to {args.out}")
    return 0


def run_calibration(
    rig: Any,
    points_kpa: list[float],
    *,
    settle_s: float,
    samples: int,
    method: str | None = None,
    max_kpa: float | None = None,
) -> Any:
    """Visit ``points_kpa`` (nominal), average ``samples`` monitor readings at each, fit a
    calibration.

    Points where the pressure no longer rises (supply limit) are dropped from a piecewise fit.
    Vents at the end.

    Returns
    -------
    pipeline.rig.calibration.Calibration
    """
    from pipeline.rig.calibration import fit_calibration

    codes, kpa = [], []
    for p in points_kpa:
        result = rig.set_kpa(p)
        rig.sleep(settle_s)
        readings = [rig.get().measured_kpa for _ in range(samples)]
        codes.append(result.dac_code)
        kpa.append(float(np.mean(readings)))
    rig.vent()
    keep = [0] + [i for i in range(1, len(kpa)) if kpa[i] > max(kpa[:i]) + 0.5]
    if (method or ("linear" if len(keep) == 2 else "piecewise")) == "linear":
        # code 0 vents (a dead zone, not on the regulator's line): fit the line through pressurised
        # points
        pressurised = [i for i in keep if codes[i] > 0]
        if len(pressurised) >= 2:
            keep, method = pressurised, "linear"
    name = f"{rig.info.name} {rig.info.version}" if rig.info else ""
    return fit_calibration(
        [codes[i] for i in keep], [kpa[i] for i in keep], method, max_kpa=max_kpa, device=name
    )


def _load(args: argparse.Namespace) -> int:
    from pipeline.rig.calibration import read_calibration, write_calibration
    from pipeline.rig.driver import PicoDriver

    if args.samples < 1:
        raise UserInputError("--samples must be at least 1")
    with PicoDriver.open(args.port, max_kpa=0.0) as rig:
        if args.tare:
            print(f"tare offset {rig.tare(min(args.samples, 255))} counts")
        if args.known_n is not None:
            if args.known_n == 0:
                raise UserInputError("--known-n must be non-zero (N)")
            scale = rig.get_scale()
            reading = float(np.mean(rig.load_samples(args.samples)))
            new_scale = scale * reading / args.known_n
            rig.set_scale(new_scale)
            print(f"scale {new_scale:.2f} counts/N (was {scale:.2f})")
            if args.calibration is not None:
                import dataclasses

                cal = read_calibration(args.calibration)
                write_calibration(
                    args.calibration, dataclasses.replace(cal, load_counts_per_newton=new_scale)
                )
        forces = rig.load_samples(args.samples)
        print(
            f"load {np.mean(forces):.4f} N (sd "
            f"{np.std(forces, ddof=1) if forces.size > 1 else 0.0:.4f} N, n={forces.size})"
        )
    return 0
