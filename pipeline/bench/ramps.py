"""``python -m pipeline bench ramps``: rendered ramp sets of bodies without a drawn line, measured
as a user measures them, with and without the second look against the ramp's own photos.

Each set is one actuator's two ramps (0 -> 260 kPa -> 0 in 20 kPa steps) of a body scene,
rendered (``python -m pipeline synth``), then set up as a lab would from what it knows: the
``background`` key removed (no photo of the empty scene), ``sealed_end_mm`` the length that does
not bend (the renderer's sealed end and tip cap) and ``fixed_direction_deg`` as rendered.  Both
measurements run on the same photos in one call (``measure_photoset(second_look=False)`` and
the default), and are scored against ``truth.csv``: photos within 5 and 10 deg, ``ok`` rows,
``ok`` rows 5-10 and over 10 deg off, rows measured again (kept), seconds.  ``--camera auto``
first gives every photo its own exposure and white balance, as a phone left on automatic does
(:func:`pipeline.bench.realscenes.through_camera`).

Examples
--------
>>> SETS[0]
RampSet(material='DS20', scene='grey_dots_clear', seed=1, width=1280, height=960)
>>> HELD_OUT[0].name
'grey_dots_clear_SS50_s5_1280x960'
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from pipeline.bench.realscenes import CAMERAS, through_camera
from pipeline.measure.quality import NOTE_RAMP_BACKGROUND


@dataclass(frozen=True)
class RampSet:
    """One rendered set: a material's two ramps of one scene, at one size."""

    material: str
    scene: str
    seed: int
    width: int
    height: int

    @property
    def name(self) -> str:
        return f"{self.scene}_{self.material}_s{self.seed}_{self.width}x{self.height}"


#: the translucent body on grey (the seven ramp sets of docs/body.md), then one set of each
#: other body scene
SETS: tuple[RampSet, ...] = (
    RampSet("DS20", "grey_dots_clear", 1, 1280, 960),
    RampSet("DS20", "grey_dots_clear", 13, 1280, 960),
    RampSet("DS30", "grey_dots_clear", 7, 1280, 960),
    RampSet("SS40", "grey_dots_clear", 9, 1280, 960),
    RampSet("DS20", "grey_dots_clear", 35, 1280, 720),
    RampSet("DS30", "grey_dots_clear", 41, 1280, 960),
    RampSet("DS20", "grey_dots_clear", 43, 1280, 720),
    RampSet("DS20", "green_fibre", 21, 1280, 960),
    RampSet("DS20", "dark_translucent", 23, 1280, 960),
    RampSet("DS20", "grey_dots", 25, 1280, 960),
)


#: six sets not used to choose ``SECOND_LOOK_APART_DEG`` (``--held-out``): stiffer bodies, other
#: seeds and sizes
HELD_OUT: tuple[RampSet, ...] = (
    RampSet("SS50", "grey_dots_clear", 5, 1280, 960),
    RampSet("SS50", "grey_dots_clear", 6, 1920, 1440),
    RampSet("SS40", "grey_dots_clear", 11, 1280, 720),
    RampSet("DS30", "grey_dots_clear", 12, 1920, 1440),
    RampSet("SS50", "dark_translucent", 13, 1280, 960),
    RampSet("DS20", "grey_dots", 14, 1920, 1440),
)


def render(spec: RampSet, folder: Path, camera: str = "clean") -> Path:
    """Render ``spec`` into ``folder`` and set it up as a user would (see the module docstring);
    each photo then goes through ``camera`` (:func:`pipeline.bench.realscenes.through_camera`,
    seeded by its place in the set)."""
    from pipeline.synth.photoset_writer import render_photoset
    from pipeline.synth.presets import SCENE_PRESETS

    out = folder / spec.name
    render_photoset(out, spec.material, actuators=1, trials=2, seed=spec.seed, scene=spec.scene,
                    step_kpa=20.0, scene_overrides={"width": spec.width, "height": spec.height})
    scene = SCENE_PRESETS[spec.scene]
    yaml = (out / "photoset.yaml").read_text()
    kept = "".join(line for line in yaml.splitlines(keepends=True) if "background" not in line)
    (out / "photoset.yaml").write_text(
        kept + f"sealed_end_mm: {scene.sealed_end_mm + scene.tip_cap_mm:g}\n"
    )
    if camera != "clean":
        for i, name in enumerate(pd.read_csv(out / "manifest.csv")["image"]):
            photo = cv2.imread(str(out / name))
            assert photo is not None  # just rendered
            cv2.imwrite(str(out / name), through_camera(photo, camera, seed=i),
                        [cv2.IMWRITE_JPEG_QUALITY, scene.jpeg_quality])
    return out


def score(folder: Path, angles: pd.DataFrame) -> dict[str, int]:
    """Counts of one measured set against its ``truth.csv``."""
    truth = pd.read_csv(folder / "truth.csv").set_index("image")["psi_deg"]
    # in the rows' order (not an index-aligned union, whose order need not be theirs)
    e = np.abs(angles["psi_deg"].to_numpy(float) - truth.reindex(angles["image"]).to_numpy(float))
    ok = (angles["status"] == "ok").to_numpy()
    again = angles["reason"].fillna("").astype(str).str.contains(NOTE_RAMP_BACKGROUND, regex=False)
    return {
        "photos": len(angles),
        "within_5": int((e <= 5).sum()),
        "within_10": int((e <= 10).sum()),
        "ok": int(ok.sum()),
        "ok_5_10_off": int((ok & (e > 5) & (e <= 10)).sum()),
        "ok_over_10_off": int((ok & (e > 10)).sum()),
        "measured_again": int(again.sum()),
    }


def main(argv: Sequence[str] | None = None) -> int:
    """Render the sets, measure each both ways, print one row per set and way, and the totals."""
    from pipeline.photoset_measure import measure_photoset

    parser = argparse.ArgumentParser(
        prog="python -m pipeline bench ramps", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--sets", type=int, default=len(SETS),
                        help=f"the first N of the {len(SETS)} sets (default all)")
    parser.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    parser.add_argument("--camera", choices=CAMERAS, default="clean",
                        help="what the camera does to each photo (auto: its own exposure and "
                             "white balance; see bench realscenes --help) (default clean)")
    parser.add_argument("--held-out", action="store_true",
                        help=f"the {len(HELD_OUT)} sets not used to choose the threshold of two "
                             "looks that disagree (docs/body.md), instead")
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-ramps-") as tmp:
        for spec in (HELD_OUT if args.held_out else SETS)[: args.sets]:
            folder = render(spec, Path(tmp), args.camera)
            for second_look in (False, True):
                t0 = time.perf_counter()
                angles = measure_photoset(folder, jobs=args.jobs, second_look=second_look)
                rows.append({
                    "set": spec.name, "second_look": second_look, **score(folder, angles),
                    "seconds": round(time.perf_counter() - t0, 1),
                })
    table = pd.DataFrame(rows)
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        print(table.to_string(index=False))
        print()
        print(table.groupby("second_look").sum(numeric_only=True).to_string())
    return 0
