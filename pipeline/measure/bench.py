"""Benchmark of the angle measurement: accuracy per method and speed, printed as tables.

``python -m pipeline.measure.bench [--n N] [--seed S]``

Accuracy, on synthetic photos with exact ground truth (:mod:`pipeline.synth`):

- nominal: ``lab`` scenes (noise, blur, JPEG 90, textured table, lighting gradient, vignetting,
  grey distractor marks, clamp and tube) with camera tilt 0-3 deg, psi uniform in -300..300;
- near straight: |psi| < 3 deg;
- non-constant curvature: ``bulge`` 0.2-0.6 (the renderer's law, kappa ~ 1 - b cos 2 pi u),
  psi in -250..100; and ``nonconstant_other``: a curvature bump off-centre or rising towards
  the tip (profiles outside that law, and outside the ``turning`` model's first terms);
- per method: median and 95th percentile of |error|, max |error| of rows with status ok, and the
  count of ``ok`` rows wrong by more than 5 deg.

Speed, per image, single OpenCV thread (as in the pool workers): the whole measurement from the
file (read, decode once at reduced size in grey, extract on a halved copy, refine the centre line
on the decoded image, fit) against ``cv2.imread`` alone on the same
JPEG, at 1280x960 and 4000x3000; and a skeletonize-then-circle-fit baseline (full decode, same
mask, :func:`skimage.morphology.skeletonize` of the frame, the skeleton pixels of the chosen
line fitted by Hyper; scikit-image is used here only).  The baseline has no ordering of its points, so its psi sign is taken from
the truth and its error is on |psi|.  Finally ``measure_photoset`` with ``--jobs`` 1 and 2.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from pipeline.measure.core import DEFAULT_METHOD, decode_for_work, measure_decoded, measure_file
from pipeline.measure.estimators import METHODS, hyper
from pipeline.measure.extract import _candidates, _choose, line_mask
from pipeline.synth import render_actuator, scene_from

L0_MM = 180.0
#: the --jobs scaling set lists every rendered photo this many times (as separate trials)
COPIES = 4


def _profile_curve(psi_deg: float, kind: str, n: int = 20001) -> np.ndarray:
    """Centre line (mm) whose curvature follows a profile outside the renderer's bulge law."""
    from scipy.integrate import cumulative_trapezoid

    u = np.linspace(0.0, 1.0, n)
    w = 1 + 1.5 * np.exp(-(((u - 0.4) / 0.15) ** 2)) if kind == "bump" else 1 + 2.0 * u**3
    w = w / np.trapezoid(w, u)
    theta = np.deg2rad(psi_deg) * cumulative_trapezoid(w, u, initial=0.0)
    return np.c_[cumulative_trapezoid(np.cos(theta), u * L0_MM, initial=0.0),
                 cumulative_trapezoid(np.sin(theta), u * L0_MM, initial=0.0)]


def _cases(kind: str, n: int, rng: np.random.Generator) -> list[tuple[float, float, float]]:
    """(psi_deg, bulge, tilt_deg) per image."""
    if kind == "nominal":
        return [(float(rng.uniform(-300, 300)), 0.0, float(rng.uniform(0, 3))) for _ in range(n)]
    if kind == "near_straight":
        return [(float(rng.uniform(-3, 3)), 0.0, float(rng.uniform(0, 3))) for _ in range(max(n // 2, 4))]
    return [(float(rng.uniform(-250, 100)), float(rng.uniform(0.2, 0.6)), 1.0) for _ in range(max(n // 2, 4))]


def accuracy(n: int, seed: int) -> pd.DataFrame:
    """One row per image x method: truth, psi, error, status."""
    rng = np.random.default_rng(seed)
    from pipeline.synth import render_curve

    rows = []
    for kind in ("nominal", "near_straight", "nonconstant", "nonconstant_other"):
        for i, (psi, bulge, tilt) in enumerate(_cases(kind, n, rng)):
            scene = scene_from("lab", tilt_deg=tilt, tilt_azimuth_deg=float(rng.uniform(0, 180)))
            if kind == "nonconstant_other":
                pts = _profile_curve(psi, "bump" if i % 2 else "tip")
                r = render_curve(pts, scene, seed=seed * 1000 + i + 100 * len(kind))
            else:
                r = render_actuator(psi, L0_MM, scene, seed=seed * 1000 + i + 100 * len(kind), bulge=bulge)
            data = np.frombuffer(r.jpeg_bytes, np.uint8)
            img, f = decode_for_work(data, grey=True)  # as measure_file / the workers do
            for method in METHODS:
                res = measure_decoded(data, img, f, l0_mm=L0_MM, mm_per_px=scene.mm_per_px,
                                      fixed_end_px=r.fixed_end_px, method=method)
                rows.append({"kind": kind, "method": method, "psi_true": psi, "psi_deg": res.psi_deg,
                             "error": res.psi_deg - psi, "status": res.status})
    return pd.DataFrame(rows)


def accuracy_table(df: pd.DataFrame) -> pd.DataFrame:
    """Median / p95 / max-ok |error| and count of ok rows off by > 5 deg, per kind and method."""
    out = []
    for (kind, method), g in df.groupby(["kind", "method"], sort=False):
        e = g["error"].abs()
        ok = g["status"] == "ok"
        out.append({"kind": kind, "method": method, "n": len(g), "median_abs_deg": e.median(),
                    "p95_abs_deg": e.quantile(0.95), "max_abs_deg": e.max(),
                    "ok": int(ok.sum()), "ok_over_5deg": int((ok & (e > 5)).sum())})
    return pd.DataFrame(out)


def _skeleton_psi(path: Path, mm_per_px: float, fixed_end: tuple[float, float]) -> float:
    from skimage.morphology import skeletonize

    img = cv2.imread(str(path))
    mask, _ = line_mask(img)
    skel = skeletonize(mask.astype(bool))  # the whole frame, as a straightforward pipeline does
    cands = _candidates(mask, fixed_end)
    best, _ = _choose(cands, 0.03 * float(np.hypot(*img.shape[:2])))
    h, w = best.sub.shape
    ys, xs = np.nonzero(skel[best.y0 : best.y0 + h, best.x0 : best.x0 + w] & (best.sub > 0))
    pts = np.c_[xs, -ys].astype(float)
    return float(abs(np.rad2deg(hyper(pts, np.random.default_rng(0)).kappa_per_px / mm_per_px * L0_MM)))


def _median_time(fn, repeats: int = 3) -> float:
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def speed(n: int, seed: int, workdir: Path) -> pd.DataFrame:
    """Per-image seconds: cv2.imread, our measurement, skeleton baseline; with errors."""
    rng = np.random.default_rng(seed + 7)
    rows = []
    for width, height in ((1280, 960), (4000, 3000)):
        scene = scene_from("lab", width=width, height=height)
        for i in range(n):
            psi = float(rng.uniform(-300, 300))
            r = render_actuator(psi, L0_MM, scene, seed=seed * 500 + i)
            path = workdir / f"s{width}_{i}.jpg"
            path.write_bytes(r.jpeg_bytes)
            t_read = _median_time(lambda: cv2.imread(str(path)))
            t_ours = _median_time(lambda: measure_file(path, l0_mm=L0_MM, mm_per_px=scene.mm_per_px, fixed_end_px=r.fixed_end_px))
            res, _ = measure_file(path, l0_mm=L0_MM, mm_per_px=scene.mm_per_px, fixed_end_px=r.fixed_end_px)
            t0 = time.perf_counter()
            skel = _skeleton_psi(path, scene.mm_per_px, r.fixed_end_px)
            t_skel = time.perf_counter() - t0
            rows.append({"size": f"{width}x{height}", "imread_s": t_read, "ours_s": t_ours, "skeleton_s": t_skel,
                         "ours_abs_err": abs(res.psi_deg - psi), "ours_absmag_err": abs(abs(res.psi_deg) - abs(psi)),
                         "skeleton_absmag_err": abs(skel - abs(psi))})
    return pd.DataFrame(rows)


def scaling(n: int, seed: int, workdir: Path) -> dict[str, float]:
    """Wall time of measure_photoset with 1 and 2 workers on one synthetic 4000x3000 set."""
    from pipeline.measure.photoset_measure import measure_photoset
    from pipeline.photoset import write_manifest, write_settings

    folder = workdir / "set"
    folder.mkdir()
    scene = scene_from("lab", width=4000, height=3000)
    rows = []
    for i, psi in enumerate(np.linspace(210, -220, n)):
        r = render_actuator(float(psi), L0_MM, scene, seed=seed + i)
        (folder / f"p{i:03d}.jpg").write_bytes(r.jpeg_bytes)
        for trial in range(COPIES):  # more photos without more rendering: hard links, new names
            name = f"p{i:03d}.jpg" if trial == 0 else f"p{i:03d}_t{trial}.jpg"
            if trial:
                (folder / name).hardlink_to(folder / f"p{i:03d}.jpg")
            rows.append({"image": name, "pressure_kpa": float(i), "direction": "up", "material": "DS20",
                         "actuator": "A1", "trial": str(trial + 1), "step": i,
                         "fixed_end_x": r.fixed_end_px[0], "fixed_end_y": r.fixed_end_px[1]})
    write_manifest(folder, pd.DataFrame(rows))
    write_settings(folder, {"l0_mm": L0_MM, "mm_per_px": scene.mm_per_px})
    out = {}
    for jobs in (1, 2):
        t0 = time.perf_counter()
        measure_photoset(folder, jobs=jobs)
        out[f"jobs={jobs}"] = time.perf_counter() - t0
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print its tables."""
    ap = argparse.ArgumentParser(prog="python -m pipeline.measure.bench", description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=60, help="nominal images for accuracy (half as many near-straight and bulged)")
    ap.add_argument("--n-speed", type=int, default=8, help="images per resolution for the speed table")
    ap.add_argument("--n-set", type=int, default=32, help="photos in the --jobs scaling set")
    ap.add_argument("--seed", type=int, default=1, help="seed of the synthetic cases")
    args = ap.parse_args(argv)
    cv2.setNumThreads(1)
    pd.set_option("display.width", 160)
    t0 = time.perf_counter()
    acc = accuracy_table(accuracy(args.n, args.seed))
    print(f"== accuracy (deg), lab scenes, tilt 0-3 deg, default method {DEFAULT_METHOD}")
    print(acc.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    with tempfile.TemporaryDirectory() as tmp:
        sp = speed(args.n_speed, args.seed, Path(tmp))
        print("\n== speed per image (ms, median over images; 1 OpenCV thread)")
        g = sp.groupby("size", sort=False)
        tab = pd.DataFrame({
            "imread_ms": g["imread_s"].median() * 1e3,
            "ours_ms": g["ours_s"].median() * 1e3,
            "ours/imread": g.apply(lambda d: float(np.median(d["ours_s"] / d["imread_s"]))),
            "skeleton_ms": g["skeleton_s"].median() * 1e3,
            "skeleton/ours": g.apply(lambda d: float(np.median(d["skeleton_s"] / d["ours_s"]))),
            "ours_med_err": g["ours_abs_err"].median(),
            "ours_|psi|_med_err": g["ours_absmag_err"].median(),
            "skel_|psi|_med_err": g["skeleton_absmag_err"].median(),
        })
        print(tab.to_string(float_format=lambda v: f"{v:.3f}"))
        sc = scaling(args.n_set, args.seed, Path(tmp))
        print(f"\n== measure_photoset on {COPIES * args.n_set} lab photos (4000x3000 JPEG): "
              + ", ".join(f"{k}: {v:.2f} s" for k, v in sc.items())
              + f", speed-up {sc['jobs=1'] / sc['jobs=2']:.2f}x")
    print(f"\n(bench took {time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
