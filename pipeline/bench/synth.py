"""Rendering benchmark: the default synthetic campaign, images per second; or one photo per scene.

``python -m pipeline bench synth [--quick] [--jobs N] [--scene lab] [--out DIR]``
``python -m pipeline bench synth --photos [--repeats R]``

The default campaign is 4 materials x 3 actuators x 6 trials of full ramps (10 kPa steps up to
260 kPa or psi = -psi0 and back) at 1280x960 JPEG; the target is under 2 minutes on 2 cores.
``--quick`` renders 1 actuator x 1 trial per material (a smoke run).

``--photos`` times, on one core (OpenCV single-threaded), the parts of one photo for every
preset at 1280x960 and 4000x3000: the static backdrop (once per ramp), the photo itself (the
actuator drawn over it, noise added), its JPEG encoding and their sum per photo of a ramp; each
the median of ``--repeats`` runs over a few angles, side by side with the ``lab`` line scene as
the ratio ``/ lab``.  The target for a 1280x960 body photo: under 0.2 s.  Prints the figures;
asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

MATERIALS = ("DS20", "DS30", "SS40", "SS50")
PHOTO_SIZES = ((1280, 960), (4000, 3000))


def photo_times(preset: str, width: int, height: int, repeats: int = 5) -> dict[str, float]:
    """Median seconds of backdrop, photo and JPEG for one preset and size (single-threaded OpenCV).

    Keys ``backdrop``, ``photo``, ``jpeg`` (wall clock), ``per_photo`` (photo + jpeg), ``single``
    (all three), and ``per_photo_cpu``, ``single_cpu``: the same in CPU time of this process,
    which a machine shared with other jobs inflates less than the wall clock.
    """
    import cv2
    import numpy as np

    from pipeline.synth.backdrop import child_seed, make_backdrop
    from pipeline.synth.camera import make_camera
    from pipeline.synth.centreline import actuator_centreline_mm
    from pipeline.synth.presets import scene_from
    from pipeline.synth.scene import compose_photo, world_extent_mm

    cv2.setNumThreads(1)
    scene = scene_from(preset, width=width, height=height)
    curves = [actuator_centreline_mm(psi, 195.0, scene) for psi in (-150.0, 30.0, 180.0)]
    extent = np.vstack(
        [
            world_extent_mm(c, scene.body_width_mm, scene.tip_cap_mm, scene.sealed_end_mm)
            for c in curves
        ]
    )
    camera = make_camera(scene, rotation_deg=0.0, extent_mm=extent)
    rows = []
    for k in range(repeats):
        w0, c0 = time.perf_counter(), time.process_time()
        backdrop = make_backdrop(scene, camera, seed=child_seed(1, k), keepout_mm=curves)
        w1, c1 = time.perf_counter(), time.process_time()
        r = compose_photo(
            curves[k % len(curves)],
            scene,
            camera,
            backdrop,
            scene.body_width_mm,
            np.random.default_rng(k),
        )
        w2 = time.perf_counter()
        _ = r.jpeg_bytes
        w3, c3 = time.perf_counter(), time.process_time()
        rows.append((w1 - w0, w2 - w1, w3 - w2, c3 - c1, c3 - c0))
    med = np.median(np.array(rows), axis=0)
    return {"backdrop": med[0], "photo": med[1], "jpeg": med[2], "per_photo": med[1] + med[2],
            "single": med[0] + med[1] + med[2], "per_photo_cpu": med[3], "single_cpu": med[4]}


def photos_report(repeats: int) -> None:
    """Print :func:`photo_times` for every preset and size, with ratios to ``lab``."""
    from pipeline.synth.presets import SCENE_PRESETS

    print(
        f"synth photo bench: one core, median of {repeats}, seconds (wall clock; cpu = this "
        "process's CPU time); "
        f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cpus"
    )
    for width, height in PHOTO_SIZES:
        print(
            f"  {width}x{height}  {'scene':17s} {'backdrop':>8s} {'photo':>7s} {'jpeg':>6s} "
            f"{'per photo':>9s} "
            f"{'/ lab':>6s} {'cpu':>6s} {'alone':>7s} {'cpu':>6s}"
        )
        base = photo_times("lab", width, height, repeats)
        for preset in ["lab", *(p for p in SCENE_PRESETS if p != "lab")]:
            t = base if preset == "lab" else photo_times(preset, width, height, repeats)
            print(
                f"  {'':{len(str(width)) + len(str(height)) + 1}s}  {preset:17s} "
                f"{t['backdrop']:8.3f} {t['photo']:7.3f} "
                f"{t['jpeg']:6.3f} {t['per_photo']:9.3f} {t['per_photo'] / base['per_photo']:6.2f} "
                f"{t['per_photo_cpu']:6.3f} {t['single']:7.3f} {t['single_cpu']:6.3f}"
            )
    print(
        "  per photo = photo + jpeg (a ramp reuses its backdrop); alone = one photo with its own "
        "backdrop; "
        "target: a 1280x960 body photo < 0.2 s"
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark and print images/s per material and in total."""
    from pipeline.synth.photoset_writer import render_photoset

    p = argparse.ArgumentParser(
        prog="python -m pipeline bench synth",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--quick", action="store_true", help="1 actuator x 1 trial per material instead of 3 x 6"
    )
    p.add_argument(
        "--jobs",
        type=int,
        default=os.cpu_count() or 1,
        help="worker processes (default: all cores)",
    )
    p.add_argument("--scene", default="lab", help="scene preset (default lab)")
    p.add_argument(
        "--out",
        default=None,
        help="keep the photo sets in this folder (default: a temporary one, deleted)",
    )
    p.add_argument(
        "--photos",
        action="store_true",
        help="time one photo per preset and size instead of the campaign",
    )
    p.add_argument("--repeats", type=int, default=5, help="runs per figure of --photos (default 5)")
    args = p.parse_args(argv)
    if args.photos:
        photos_report(max(1, args.repeats))
        return 0
    actuators, trials = (1, 1) if args.quick else (3, 6)
    root = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="synth_bench_"))
    total_n, total_t, total_bytes = 0, 0.0, 0
    print(
        f"synth bench: {len(MATERIALS)} materials x {actuators} x {trials} ramps, scene "
        f"{args.scene}, "
        f"1280x960 JPEG, jobs {args.jobs}, cpus {os.cpu_count()}"
    )
    try:
        for material in MATERIALS:
            out = root / material
            t0 = time.perf_counter()
            truth = render_photoset(
                out,
                material,
                actuators=actuators,
                trials=trials,
                seed=1,
                scene=args.scene,
                jobs=args.jobs,
            )
            dt = time.perf_counter() - t0
            size = sum(f.stat().st_size for f in out.glob("*.jpg"))
            total_n, total_t, total_bytes = total_n + len(truth), total_t + dt, total_bytes + size
            print(
                f"  {material}: {len(truth):5d} images in {dt:6.1f} s = {len(truth) / dt:6.1f} "
                "images/s, "
                f"{size / len(truth) / 1024:.0f} KiB/image"
            )
        print(f"  total: {total_n} images in {total_t:.1f} s = {total_n / total_t:.1f} images/s "
              f"({total_bytes / 2**20:.0f} MiB); target for the full campaign: < 120 s")
    finally:
        if not args.out:
            shutil.rmtree(root, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
