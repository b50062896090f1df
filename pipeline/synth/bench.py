"""Rendering benchmark: the default synthetic campaign, images per second.

``python -m pipeline.synth.bench [--quick] [--jobs N] [--scene lab] [--out DIR]``

The default campaign is 4 materials x 3 actuators x 6 trials of full ramps (10 kPa steps up to
260 kPa or psi = -psi0 and back) at 1280x960 JPEG; the target is under 2 minutes on 2 cores.
``--quick`` renders 1 actuator x 1 trial per material (a smoke run).  Prints the figures; asserts
nothing.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

MATERIALS = ("DS20", "DS30", "SS40", "SS50")


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print images/s per material and in total."""
    from pipeline.synth.photoset_writer import render_photoset

    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="1 actuator x 1 trial per material instead of 3 x 6")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="worker processes (default: all cores)")
    p.add_argument("--scene", default="lab", help="scene preset (default lab)")
    p.add_argument("--out", default=None, help="keep the photo sets in this folder (default: a temporary one, deleted)")
    args = p.parse_args(argv)
    actuators, trials = (1, 1) if args.quick else (3, 6)
    root = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="synth_bench_"))
    total_n, total_t, total_bytes = 0, 0.0, 0
    print(f"synth bench: {len(MATERIALS)} materials x {actuators} x {trials} ramps, scene {args.scene}, "
          f"1280x960 JPEG, jobs {args.jobs}, cpus {os.cpu_count()}")
    try:
        for material in MATERIALS:
            out = root / material
            t0 = time.perf_counter()
            truth = render_photoset(out, material, actuators=actuators, trials=trials, seed=1, scene=args.scene,
                                    jobs=args.jobs)
            dt = time.perf_counter() - t0
            size = sum(f.stat().st_size for f in out.glob("*.jpg"))
            total_n, total_t, total_bytes = total_n + len(truth), total_t + dt, total_bytes + size
            print(f"  {material}: {len(truth):5d} images in {dt:6.1f} s = {len(truth) / dt:6.1f} images/s, "
                  f"{size / len(truth) / 1024:.0f} KiB/image")
        print(f"  total: {total_n} images in {total_t:.1f} s = {total_n / total_t:.1f} images/s "
              f"({total_bytes / 2**20:.0f} MiB); target for the full campaign: < 120 s")
    finally:
        if not args.out:
            shutil.rmtree(root, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
