"""Benchmark of the angle measurement: accuracy per method and speed, printed as tables.

``python -m pipeline bench measure [--n N] [--seed S]``

Accuracy, on synthetic photos with exact ground truth (:mod:`pipeline.synth`):

- nominal: ``lab`` scenes (noise, blur, JPEG 90, textured table, lighting gradient, vignetting,
  grey distractor marks, clamp and tube) with camera tilt 0-3 deg, psi uniform in -300..300;
- near straight: |psi| < 3 deg;
- non-constant curvature: ``bulge`` 0.2-0.6 (the renderer's law, kappa ~ 1 - b cos 2 pi u),
  psi in -250..100; and ``nonconstant_other``: a curvature bump off-centre or rising towards
  the tip (profiles outside that law, and outside the ``turning`` model's first terms);
- per method: median and 95th percentile of |error|, max |error| of rows with status ok, and the
  count of ``ok`` rows wrong by more than 5 deg.

Speed, per image, single OpenCV thread (as in the pool workers), ``--n-speed`` images at
1280x960 and 4000x3000: the whole measurement from the file (read, decode once at reduced size
in grey, extract on a halved copy, refine the centre line on the decoded image, fit) against
``cv2.imread`` alone on the same JPEG; against a skeletonize-then-circle-fit baseline (full
colour decode, same mask, :func:`skimage.morphology.skeletonize` of the whole frame, the
skeleton pixels of the chosen line fitted by Hyper; scikit-image is used here only); and the
decode floor ``cv2.imdecode(bytes, IMREAD_REDUCED_GRAYSCALE_8)``, so skeleton / floor is the
largest speed-up any method that decodes the file could reach.  Every method is timed as the
median of 3 runs.  Each psi/seed is rendered at camera tilt 0 (the estimators' own accuracy;
the file that is timed) and at the lab tilt of 1 deg (a scale error ``mm_per_px`` cannot
remove, shared by both methods).  The baseline has no ordering of its points, so it gives
|psi|; both methods are scored on |psi| on the same images: median |error| each, the paired
median of |err_ours| - |err_skeleton| with a 95 % bootstrap CI, and the share of images where
ours is at least as accurate.  Verdict per size, "10x at equal or better accuracy: met" when
skeleton/ours >= 10 and the CI upper bound of that paired median at tilt 0 is <= 0.01 deg.
Finally ``measure_photoset`` with ``--jobs`` 1 and 2.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Sequence
from functools import partial
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from pipeline.measure.colors import BLACK
from pipeline.measure.core import DEFAULT_METHOD, decode_for_work, measure_decoded, measure_file
from pipeline.measure.estimators import METHODS, algebraic_circle, hyper
from pipeline.measure.extract import line_component, line_mask
from pipeline.measure.settings import resolve_settings
from pipeline.synth import render_actuator, scene_from

L0_MM = 180.0
#: the --jobs scaling set lists every rendered photo this many times (as separate trials):
#: 32 x 16 = 512 photos, the size of a real campaign of one material (3 actuators x 6 trials)
COPIES = 16


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
        return [
            (float(rng.uniform(-3, 3)), 0.0, float(rng.uniform(0, 3)))
            for _ in range(max(n // 2, 4))
        ]
    return [
        (float(rng.uniform(-250, 100)), float(rng.uniform(0.2, 0.6)), 1.0)
        for _ in range(max(n // 2, 4))
    ]


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
                r = render_actuator(
                    psi, L0_MM, scene, seed=seed * 1000 + i + 100 * len(kind), bulge=bulge
                )
            data = np.frombuffer(r.jpeg_bytes, np.uint8)
            img, f = decode_for_work(data, grey=True)  # as measure_file / the workers do
            assert img is not None  # the photo just rendered
            for method in METHODS:
                settings = resolve_settings(
                    l0_mm=L0_MM, mm_per_px=scene.mm_per_px, fixed_end=list(r.fixed_end_px)
                )
                res = measure_decoded(data, img, f, settings, method=method)
                rows.append(
                    {
                        "kind": kind,
                        "method": method,
                        "psi_true": psi,
                        "psi_deg": res.psi_deg,
                        "error": res.psi_deg - psi,
                        "status": res.status,
                    }
                )
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
    assert img is not None  # a photo the bench wrote
    mask, _ = line_mask(img, BLACK)
    skel = skeletonize(mask.astype(bool))  # the whole frame, as a straightforward pipeline does
    x0, y0, sub = line_component(mask, fixed_end, 0.03 * float(np.hypot(*img.shape[:2])))
    h, w = sub.shape
    ys, xs = np.nonzero(skel[y0 : y0 + h, x0 : x0 + w] & (sub > 0))
    pts = np.c_[xs, -ys].astype(float)
    return float(
        abs(np.rad2deg(hyper(pts, np.random.default_rng(0)).kappa_per_px / mm_per_px * L0_MM))
    )


def _median_time(fn, repeats: int = 3) -> float:
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


#: sizes (width, height) of the speed comparison, as in issue 6's target
SPEED_SIZES: tuple[tuple[int, int], ...] = ((1280, 960), (4000, 3000))
#: issue 6: at least this many times faster than the skeleton baseline ...
TARGET_SPEEDUP = 10.0
#: ... at equal or better accuracy: the upper 95 % bound of the paired median difference
#: median(|err_ours| - |err_skeleton|) at tilt 0 must be at most this (deg)
EQUAL_ACCURACY_TOL_DEG = 0.01


def _bare_circle_px(data: np.ndarray) -> float:
    """The least a measurement could do: radius (decoded px) of a Hyper circle through the biggest
    dark blob.

    Decode at 1/4 size in grey, Otsu threshold, largest connected component, algebraic fit of
    its pixels: no colour, no clamp cut, no ordering or sign, no quality checks, and often the
    wrong blob.  Timed only, as a floor for the cost of any real measurement; never scored.
    """
    grey = cv2.imdecode(data, cv2.IMREAD_REDUCED_GRAYSCALE_4)
    assert grey is not None  # a photo the bench rendered
    _, mask = cv2.threshold(grey, 0, 255, cv2.THRESH_BINARY_INV | cv2.THRESH_OTSU)
    _, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    k = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    ys, xs = np.nonzero(labels == k)
    (a, b, c, d), scale = algebraic_circle(np.c_[xs, ys].astype(float), "hyper")
    return float(np.sqrt(b * b + c * c - 4 * a * d) / (2 * abs(a)) * scale)


def speed(n: int, seed: int, workdir: Path, sizes: tuple[tuple[int, int], ...] = SPEED_SIZES,
          repeats: int = 3) -> pd.DataFrame:
    """Per image: seconds of imread, ours, the skeleton baseline and the decode floor; errors at two
    tilts.

    Each image (psi uniform in -300..300, one seed) is rendered twice with the ``lab`` scene:
    with ``tilt_deg=0`` (the estimators' own accuracy) and with the preset's camera tilt (1 deg;
    ``mm_per_px`` is then exact only at the image centre, a scale error both methods share).
    Timing is on the tilt-0 file only (it does not depend on tilt); every method is timed as
    the median of ``repeats`` runs after one untimed run (that run's result is the one scored).

    Parameters
    ----------
    n : int
        Images per size.
    seed : int
        Seed of psi and of the renderer.
    workdir : Path
        Folder for the JPEG files.
    sizes : tuple of (int, int)
        Image sizes (width, height) in px.
    repeats : int
        Timed runs per method and image (the median is kept).

    Returns
    -------
    pandas.DataFrame
        One row per image and tilt: ``size``, ``image``, ``tilt_deg``, ``psi_true``,
        ``ours_psi``, ``ours_status``, ``skeleton_psi`` (|psi|; the baseline has no sign),
        ``ours_abs_err`` (signed psi), ``ours_absmag_err`` and ``skeleton_absmag_err`` (on |psi|,
        deg), and the tilt-0 file's timings repeated on both rows: ``imread_s``, ``ours_s``,
        ``skeleton_s``, ``decode_floor_s`` (``cv2.imdecode`` of the in-memory bytes with
        ``IMREAD_REDUCED_GRAYSCALE_8``, no file read) and ``bare_s`` (:func:`_bare_circle_px`
        on the same bytes).
    """
    rng = np.random.default_rng(seed + 7)
    rows = []
    for width, height in sizes:
        scenes = {0.0: scene_from("lab", width=width, height=height, tilt_deg=0.0)}
        tilted = scene_from("lab", width=width, height=height)
        scenes[float(tilted.tilt_deg)] = tilted
        for i in range(n):
            psi = float(rng.uniform(-300, 300))
            timing: dict[str, float] = {}
            for tilt, scene in scenes.items():  # tilt 0 first: its file is the one timed
                r = render_actuator(psi, L0_MM, scene, seed=seed * 500 + i)
                path = workdir / f"s{width}_{i}_tilt{tilt:g}.jpg"
                path.write_bytes(r.jpeg_bytes)
                settings = resolve_settings(
                    l0_mm=L0_MM, mm_per_px=scene.mm_per_px, fixed_end=list(r.fixed_end_px)
                )
                res, _ = measure_file(path, settings)
                skel = _skeleton_psi(path, scene.mm_per_px, r.fixed_end_px)
                if not timing:
                    data = np.frombuffer(r.jpeg_bytes, np.uint8)
                    timing = {  # partial binds this iteration's values (no late-binding lambdas)
                        "imread_s": _median_time(partial(cv2.imread, str(path)), repeats),
                        "ours_s": _median_time(partial(measure_file, path, settings), repeats),
                        "skeleton_s": _median_time(
                            partial(_skeleton_psi, path, scene.mm_per_px, r.fixed_end_px), repeats),
                        "decode_floor_s": _median_time(
                            partial(cv2.imdecode, data, cv2.IMREAD_REDUCED_GRAYSCALE_8), repeats),
                        "bare_s": _median_time(partial(_bare_circle_px, data), repeats),
                    }
                rows.append(
                    {
                        "size": f"{width}x{height}",
                        "image": i,
                        "tilt_deg": tilt,
                        "psi_true": psi,
                        "ours_psi": res.psi_deg,
                        "ours_status": res.status,
                        "skeleton_psi": skel,
                        "ours_abs_err": abs(res.psi_deg - psi),
                        "ours_absmag_err": abs(abs(res.psi_deg) - abs(psi)),
                        "skeleton_absmag_err": abs(skel - abs(psi)),
                        **timing,
                    }
                )
    return pd.DataFrame(rows)


def speed_table(sp: pd.DataFrame) -> pd.DataFrame:
    """Per size: median ms of imread, ours, skeleton and decode floor, and the speed ratios.

    Ratios ``ours/imread`` and ``skeleton/ours`` are medians of per-image ratios;
    ``max_speedup`` = skeleton ms / decode-floor ms is the largest speed-up over the baseline that
    any method which has to decode the file (even at 1/8 scale in grey) could reach;
    ``bare_ms`` is :func:`_bare_circle_px`, the least any measurement does after decoding.

    Parameters
    ----------
    sp : pandas.DataFrame
        Output of :func:`speed`.

    Returns
    -------
    pandas.DataFrame
        Indexed by ``size``.
    """
    one = sp.drop_duplicates(["size", "image"])  # timings are per image, repeated per tilt
    g = one.groupby("size", sort=False)
    tab = pd.DataFrame({
        "n": g.size(),
        "imread_ms": g["imread_s"].median() * 1e3,
        "ours_ms": g["ours_s"].median() * 1e3,
        "ours/imread": g.apply(lambda d: float(np.median(d["ours_s"] / d["imread_s"]))),
        "skeleton_ms": g["skeleton_s"].median() * 1e3,
        "skeleton/ours": g.apply(lambda d: float(np.median(d["skeleton_s"] / d["ours_s"]))),
        "decode_floor_ms": g["decode_floor_s"].median() * 1e3,
        "bare_ms": g["bare_s"].median() * 1e3,
    })
    tab["max_speedup"] = tab["skeleton_ms"] / tab["decode_floor_ms"]
    return tab


def _bootstrap_median_ci(
    d: np.ndarray, rng: np.random.Generator, resamples: int
) -> tuple[float, float]:
    """Percentile 95 % bootstrap interval of the median of ``d`` (no interpolation, so inf is
    kept)."""
    idx = rng.integers(0, d.size, size=(resamples, d.size))
    lo, hi = np.percentile(np.median(d[idx], axis=1), [2.5, 97.5], method="inverted_cdf")
    return float(lo), float(hi)


def paired_accuracy(sp: pd.DataFrame, seed: int, resamples: int = 2000) -> pd.DataFrame:
    """Ours vs the skeleton baseline on the same images, per size and tilt, errors on |psi|.

    A measurement that failed (NaN psi) counts as an infinitely large error.  ``diff`` is
    |err_ours| - |err_skeleton| per image (negative: ours is closer to the truth);
    ``med_diff`` is its median, ``ci_lo``/``ci_hi`` a 95 % percentile bootstrap interval of
    that median (``resamples`` resamples, seeded numpy Generator), ``ours_as_good`` the share
    of images with diff <= 0.

    Parameters
    ----------
    sp : pandas.DataFrame
        Output of :func:`speed`.
    seed : int
        Seed of the bootstrap.
    resamples : int
        Bootstrap resamples.

    Returns
    -------
    pandas.DataFrame
        One row per ``size`` and ``tilt_deg`` with ``n``, ``ours_med_err`` (signed psi),
        ``ours_|psi|_med_err``, ``skel_|psi|_med_err``, ``med_diff``, ``ci_lo``, ``ci_hi``,
        ``ours_as_good``.
    """
    rng = np.random.default_rng(seed)
    out = []
    for (size, tilt), g in sp.groupby(["size", "tilt_deg"], sort=False):
        ours = g["ours_absmag_err"].fillna(np.inf).to_numpy(float)
        skel = g["skeleton_absmag_err"].fillna(np.inf).to_numpy(float)
        d = np.where(ours == skel, 0.0, ours - skel)  # inf - inf would be NaN: both failed = a tie
        lo, hi = _bootstrap_median_ci(d, rng, resamples)
        out.append(
            {
                "size": size,
                "tilt_deg": tilt,
                "n": len(g),
                "ours_med_err": float(g["ours_abs_err"].fillna(np.inf).median()),
                "ours_|psi|_med_err": float(np.median(ours)),
                "skel_|psi|_med_err": float(np.median(skel)),
                "med_diff": float(np.median(d)),
                "ci_lo": lo,
                "ci_hi": hi,
                "ours_as_good": float(np.mean(d <= 0)),
            }
        )
    return pd.DataFrame(out)


def verdicts(speed_tab: pd.DataFrame, paired: pd.DataFrame, speedup: float = TARGET_SPEEDUP,
             tol_deg: float = EQUAL_ACCURACY_TOL_DEG) -> pd.Series:
    """Issue 6's target per size: "met" or "not met".

    Met when the median per-image ``skeleton/ours`` time ratio is at least ``speedup`` AND the
    accuracy is equal or better, meaning the upper bound ``ci_hi`` of the 95 % bootstrap CI of
    the paired median difference median(|err_ours| - |err_skeleton|) at tilt 0 is at most
    ``tol_deg`` deg.

    Parameters
    ----------
    speed_tab : pandas.DataFrame
        Output of :func:`speed_table` (indexed by size, column ``skeleton/ours``).
    paired : pandas.DataFrame
        Output of :func:`paired_accuracy` (columns ``size``, ``tilt_deg``, ``ci_hi``).
    speedup, tol_deg : float
        The thresholds.

    Returns
    -------
    pandas.Series
        Indexed by size.
    """
    ci_hi = paired[paired["tilt_deg"] == 0.0].set_index("size")["ci_hi"].reindex(speed_tab.index)
    met = (speed_tab["skeleton/ours"] >= speedup) & (ci_hi <= tol_deg)
    return met.map({True: "met", False: "not met"}).rename("verdict")


def print_speed(sp: pd.DataFrame, seed: int) -> None:
    """Print the speed table, the paired accuracy table and one verdict line per size."""
    fmt = "{:.3f}".format
    tab = speed_table(sp)
    print("\n== speed per image (ms, median over images; median of 3 runs each; 1 OpenCV thread)")
    print(
        "   decode_floor = cv2.imdecode(bytes, IMREAD_REDUCED_GRAYSCALE_8); max_speedup = skeleton "
        "/ decode_floor"
    )
    print(
        "   bare = decode at 1/4 + Otsu + largest component + Hyper fit, no checks (timed, never "
        "scored)"
    )
    print(tab.to_string(float_format=fmt))
    paired = paired_accuracy(sp, seed)
    print("\n== accuracy on the same images (deg; errors on |psi|, the baseline has no sign; "
          "diff = |err_ours| - |err_skel|, 95 % bootstrap CI of its median)")
    print(paired.to_string(index=False, float_format=fmt))
    print(
        f"\n   rule: 'met' = skeleton/ours >= {TARGET_SPEEDUP:g} and, at tilt 0, the CI upper "
        "bound of "
        f"the median diff <= {EQUAL_ACCURACY_TOL_DEG:g} deg"
    )
    for size, v in verdicts(tab, paired).items():
        print(
            f"   {size}: {TARGET_SPEEDUP:g}x at equal or better accuracy: {v} "
            f"(skeleton/ours {tab.loc[size, 'skeleton/ours']:.1f}x, at most "
            f"{tab.loc[size, 'max_speedup']:.1f}x "
            "for any method that decodes the file)"
        )


def _scaling_set(folder: Path, renders: list, scene, copies: int) -> None:
    """A photo set listing each rendered photo ``copies`` times (hard links, new names)."""
    from pipeline.photoset import write_manifest, write_settings

    folder.mkdir()
    rows = []
    for i, r in enumerate(renders):
        (folder / f"p{i:03d}.jpg").write_bytes(r.jpeg_bytes)
        for trial in range(copies):
            name = f"p{i:03d}.jpg" if trial == 0 else f"p{i:03d}_t{trial}.jpg"
            if trial:
                (folder / name).hardlink_to(folder / f"p{i:03d}.jpg")
            rows.append(
                {
                    "image": name,
                    "pressure_kpa": float(i),
                    "direction": "up",
                    "material": "DS20",
                    "actuator": "A1",
                    "trial": str(trial + 1),
                    "step": i,
                    "fixed_end_x": r.fixed_end_px[0],
                    "fixed_end_y": r.fixed_end_px[1],
                }
            )
    write_manifest(folder, pd.DataFrame(rows))
    write_settings(folder, {"l0_mm": L0_MM, "mm_per_px": scene.mm_per_px})


def scaling(
    n: int, seed: int, workdir: Path, copies: int = COPIES, size: tuple[int, int] = (4000, 3000)
) -> dict[str, float]:
    """Wall time (s) of measure_photoset with 1 and 2 workers on one synthetic set of ``size``
    (width, height; the bench's figure is at 4000x3000).

    Also ``"start-up, jobs=2"``: the same call on a 2-photo set, i.e. what starting the pool
    costs (forkserver preloading OpenCV/numpy/scipy), which small sets cannot amortise.
    """
    from pipeline.photoset_measure import measure_photoset

    scene = scene_from("lab", width=size[0], height=size[1])
    renders = [render_actuator(float(psi), L0_MM, scene, seed=seed + i)
               for i, psi in enumerate(np.linspace(210, -220, n))]
    _scaling_set(workdir / "set", renders, scene, copies)
    _scaling_set(workdir / "tiny", renders[:2], scene, 1)
    out = {}
    for jobs in (1, 2):
        t0 = time.perf_counter()
        measure_photoset(workdir / "set", jobs=jobs)
        out[f"jobs={jobs}"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    measure_photoset(workdir / "tiny", jobs=2)
    out["start-up, jobs=2"] = time.perf_counter() - t0
    return out


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark and print its tables."""
    ap = argparse.ArgumentParser(
        prog="python -m pipeline bench measure", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument(
        "--n",
        type=int,
        default=60,
        help="nominal images for accuracy (half as many near-straight and bulged)",
    )
    ap.add_argument(
        "--n-speed",
        type=int,
        default=40,
        help="images per resolution for the speed and paired accuracy tables (40: the paired CI at "
             "4000x3000 is then about +-0.007 deg; 16 leaves it too wide to decide)",
    )
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
        print_speed(speed(args.n_speed, args.seed, Path(tmp)), args.seed)
        sc = scaling(args.n_set, args.seed, Path(tmp))
        print(f"\n== measure_photoset on {COPIES * args.n_set} lab photos (4000x3000 JPEG): "
              + ", ".join(f"{k}: {v:.2f} s" for k, v in sc.items())
              + f", speed-up {sc['jobs=1'] / sc['jobs=2']:.2f}x")
        print("   (start-up is measure_photoset with --jobs 2 on 2 photos: the pool's fixed cost)")
    print(f"\n(bench took {time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
