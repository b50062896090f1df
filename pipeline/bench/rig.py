"""Speed of the rig software against the emulator: ``python -m pipeline bench rig``.

Prints (never asserts) the figures that decide how long a real session costs besides the
settle time: command round trips through the pty, the per-step overhead of the acquisition
loop (settle 0, a ``cmd:`` camera copying a file, atomic photo + manifest writes), the growth
of that overhead with the manifest length, and the synthetic camera / live psi measurement.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from pipeline.rig.acquire import SessionConfig, run_session
from pipeline.rig.cameras import CommandCamera, Shot
from pipeline.rig.driver import PicoDriver
from pipeline.rig.emulator import Emulator


def round_trips(n: int) -> dict[str, float]:
    """Median and 95th-percentile time (ms) of one SET and one GET through the pty."""
    set_ms, get_ms = [], []
    with Emulator(seed=0) as emu, PicoDriver.open(emu.port, max_kpa=260) as rig:
        for i in range(n):
            t0 = time.perf_counter()
            rig.set_kpa(float(i % 260))
            t1 = time.perf_counter()
            rig.get()
            t2 = time.perf_counter()
            set_ms.append((t1 - t0) * 1e3)
            get_ms.append((t2 - t1) * 1e3)
    return {
        "set_median_ms": float(np.median(set_ms)),
        "set_p95_ms": float(np.percentile(set_ms, 95)),
        "get_median_ms": float(np.median(get_ms)),
        "get_p95_ms": float(np.percentile(get_ms, 95)),
    }


def loop_overhead(trials: int, step_kpa: float, max_kpa: float, mode: str) -> dict[str, float]:
    """Per-photo time (ms) of a whole acquisition with settle 0 and a file-copying camera."""
    import cv2

    with tempfile.TemporaryDirectory() as tmp:
        photo = Path(tmp) / "shot.jpg"
        img = np.full((960, 1280, 3), 200, np.uint8)
        cv2.line(img, (100, 480), (1180, 480), (0, 0, 0), 6)
        photo.write_bytes(cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 90])[1].tobytes())
        cfg = SessionConfig(
            out_dir=Path(tmp) / "set",
            material="DS20",
            actuator="A1",
            trials=trials,
            step_kpa=step_kpa,
            max_kpa=max_kpa,
            settle_s=0.0,
            settings={"l0_mm": 270.0},
            mode=mode,
            force_samples=10,
        )
        camera = CommandCamera(f"cp {photo} {{path}}")
        with Emulator(seed=0) as emu, PicoDriver.open(emu.port, max_kpa=max_kpa) as rig:
            t0 = time.perf_counter()
            with open(os.devnull, "w") as devnull:
                result = run_session(rig, camera, cfg, progress=False, stream=devnull)
            seconds = time.perf_counter() - t0
        camera.close()
        # cost of one more row once the manifest holds every row of the session
        from pipeline.photoset import append_manifest_rows

        t1 = time.perf_counter()
        append_manifest_rows(
            cfg.out_dir,
            [
                {
                    "image": "extra.jpg",
                    "pressure_kpa": "0",
                    "direction": "up",
                    "material": "DS20",
                    "actuator": "A9",
                    "trial": "1",
                    "step": "0",
                }
            ],
        )
        append_ms = (time.perf_counter() - t1) * 1e3
    return {
        "photos": result.photos_taken,
        "per_photo_ms": seconds / max(result.photos_taken, 1) * 1e3,
        "append_row_at_end_ms": append_ms,
    }


def synthetic_costs(n: int) -> dict[str, float]:
    """Time (ms) to render one synthetic photo and to measure psi on it (live psi0 stop).

    The stop criterion swallows a failed measurement (it must never stop the rig), so the
    statuses are counted: the figure is the cost of a real measurement only when every photo
    was measured (``live_psi_measured`` = ``n``); :func:`main` refuses to print it otherwise.
    """
    from pipeline.measure import measure_image
    from pipeline.measure.core import AngleResult
    from pipeline.measure.settings import MeasureSettings, resolve_settings
    from pipeline.model import load_materials
    from pipeline.rig.acquire import psi0_stop_criterion
    from pipeline.rig.cameras import SyntheticCamera

    material = load_materials()["DS20"]
    cam = SyntheticCamera(material.name, 270.0, preset="lab", seed=0)
    settings = resolve_settings({**cam.photoset_settings(), "l0_mm": 270.0})
    statuses: list[str] = []

    def counted(image: np.ndarray, s: MeasureSettings) -> AngleResult:
        result = measure_image(image, s)
        statuses.append(result.status)
        return result

    stop = psi0_stop_criterion(material.psi0_deg, measure_image=counted)
    render, measure = [], []
    for i in range(n):
        t0 = time.perf_counter()
        data, _ = cam.capture(Shot(10.0 * i, 10.0 * i, "up", 1, i))
        render.append((time.perf_counter() - t0) * 1e3)
        t1 = time.perf_counter()
        stop(data, settings)
        measure.append((time.perf_counter() - t1) * 1e3)
    return {"synthetic_render_median_ms": float(np.median(render)),
            "live_psi_measure_median_ms": float(np.median(measure)),
            "live_psi_measured": float(sum(s != "failed" for s in statuses))}


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark and print the figures."""
    parser = argparse.ArgumentParser(prog="python -m pipeline bench rig", description=__doc__)
    parser.add_argument(
        "--round-trips", type=int, default=500, help="SET+GET pairs timed (default 500)"
    )
    parser.add_argument(
        "--synthetic", type=int, default=10, help="synthetic photos timed (default 10)"
    )
    args = parser.parse_args(argv)
    print("rig benchmark (emulator over a pty; times in ms)")
    for key, value in round_trips(args.round_trips).items():
        print(f"  {key:32s} {value:8.3f}")
    for label, kwargs in (
        (
            "paper ramp, 1 trial (53 photos)",
            {"trials": 1, "step_kpa": 10, "max_kpa": 260, "mode": "bending"},
        ),
        (
            "paper ramp, 6 trials (318 photos)",
            {"trials": 6, "step_kpa": 10, "max_kpa": 260, "mode": "bending"},
        ),
        (
            "blocked, 1 trial, 10 samples/step",
            {"trials": 1, "step_kpa": 10, "max_kpa": 260, "mode": "blocked"},
        ),
    ):
        r = loop_overhead(**kwargs)  # type: ignore[arg-type]
        print(
            f"  {label}: {r['photos']} photos, {r['per_photo_ms']:.1f} ms per photo besides "
            "settling; "
            f"one more manifest row at the end {r['append_row_at_end_ms']:.1f} ms"
        )
    costs = synthetic_costs(args.synthetic)
    if costs["live_psi_measured"] < args.synthetic:
        print(
            f"  live psi measured on {costs['live_psi_measured']:.0f} of {args.synthetic} "
            "synthetic photos: "
            "the timing would be of the failure path; not reported"
        )
        return 1
    for key in ("synthetic_render_median_ms", "live_psi_measure_median_ms"):
        print(f"  {key:32s} {costs[key]:8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
