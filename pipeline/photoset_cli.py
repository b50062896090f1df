"""``python -m pipeline photoset {init,check,calibrate,preview,pick-color}``: start, validate,
calibrate or preview a photo set."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pipeline import photoset, photoset_init
from pipeline.constants import RAMP_KEYS
from pipeline.errors import UserInputError
from pipeline.measure.settings import FREE_ENDS, POSITIVE_TURNS
from pipeline.photo_log import ClockSync

if TYPE_CHECKING:
    import pandas as pd


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define ``photoset init`` and ``photoset check``."""
    sub = parser.add_subparsers(
        dest="photoset_command", metavar="{init,check,calibrate,preview,pick-color}", required=True
    )
    init = sub.add_parser(
        "init",
        help="write a starter manifest.csv and photoset.yaml from the image file names",
        description=(
            "Write manifest.csv (and photoset.yaml when absent) from the names of the photos in "
            "DIR. "
            "Fields: {pressure_kpa} (kPa; '12p5' means 12.5), {direction} (up/down, inc/dec), "
            "{trial}, {actuator}, {material}, {step}, {_} or * (ignored). Without {direction}, "
            "photos before the highest pressure of each ramp are 'up', after it 'down'. A "
            "pattern with '/' matches the photos' paths in DIR's subfolders, e.g. "
            "'actuator{actuator}/{step}_{pressure_kpa}kPa.jpg' (chambers of one actuator: "
            "'chamber{material}/...', each its own curve). Photos named by a camera take their "
            "pressures from a logger's log at their EXIF times with --pressure-log (init DIR "
            "--pattern 'IMG_*.JPG' --pressure-log log.csv). For videos give --pressure-log: "
            "one row per video (init DIR --pattern 'GX*.MP4' --pressure-log log.csv)."
        ),
    )
    init.add_argument("folder", metavar="DIR", help="folder holding the photos")
    init.add_argument(
        "--pattern",
        required=True,
        help="file-name pattern, e.g. "
             "'{material}_{actuator}_t{trial}_{step}_{pressure_kpa}kPa.jpg'",
    )
    init.add_argument(
        "--pressures-kpa",
        metavar="SPEC",
        action="append",
        help="for file names without the pressure (a camera's IMG_0001.JPG): each ramp's "
             "pressures in photo order, '0,20,40,20,0' or LOW:HIGH:STEP ('0:180:20' = 0, 20, ..., "
             "180 and back down to 0); every actuator and trial has as many photos, in file-name "
             "order (numbers as numbers) or by {step}.  Repeat it as TRIAL=SPEC (or "
             "ACTUATOR/TRIAL=SPEC) for ramps of their own: --pressures-kpa 1=0:160:20 "
             "--pressures-kpa 2=0:180:20; without {trial} in the pattern (ramps taken one after "
             "another into one folder) the trials take the photos in that order",
    )
    init.add_argument(
        "--pressure-log",
        metavar="NAME",
        help="the pressure log (a CSV with time_s and pressure_kpa; or the logger's own clock: "
             "a 'timestamp' column of dates and times, 'Date' and 'Time' columns, or clock times "
             "alone) in DIR. For photos whose names hold no pressure: each photo's "
             "setpoint, measured pressure and direction are read from the log at the time the "
             "camera wrote into it (EXIF). For videos ('{video}' in it stands for each video's "
             "name without its ending, '{video}_pressure.csv'): writes a video photo set, one "
             "manifest row per video matching --pattern (e.g. 'GX*.MP4'), or one row of a frame "
             "sequence: --pattern 'frame_%%04d.jpg' names frame_0001.jpg, frame_0002.jpg, ... "
             "(with --fps)",
    )
    init.add_argument(
        "--fps",
        type=float,
        metavar="F",
        help="for videos: their frame rate, written as the manifest's fps (a frame sequence has "
             "none of its own; a video's own is used without it)",
    )
    init.add_argument(
        "--clock-offset-s",
        type=float,
        metavar="S",
        help="with --pressure-log, in seconds whatever the log's unit. Videos: the log's time "
             "at the video's first frame (default 0; a log of dates counts from its first row). "
             "Photos: on a log of dates and clock times, how far the logger's clock is ahead of "
             "the camera's (negative when behind; default 0, the clocks agree); on a log in "
             "seconds, the log's time at the first photo (needed, or --log-time-at)",
    )
    init.add_argument(
        "--log-time-at",
        metavar="PHOTO=TIME",
        help="with --pressure-log, for photos: PHOTO, a photo of the logger's screen with its "
             "clock in view (kept out of the set's folder, its path from it), and the log's TIME "
             "it shows, e.g. ../clock.JPG=14:00:10.1 (on a log in seconds, its time in seconds); "
             "relates the camera's clock to the logger's instead of --clock-offset-s, with no "
             "sign to get wrong",
    )
    init.add_argument(
        "--material", help="material for every photo when the pattern has no {material}"
    )
    init.add_argument(
        "--actuator", help="actuator label when the pattern has no {actuator} (default A1)"
    )
    init.add_argument(
        "--trial",
        help="trial label when the pattern has no {trial} (default 1; several videos of one "
        "actuator: 1, 2, ... in name order)",
    )
    init.add_argument(
        "--l0-mm",
        type=float,
        help="length of the marked inextensible layer, mm (written to photoset.yaml)",
    )
    init.add_argument(
        "--mm-per-px",
        type=float,
        help="image scale, mm per pixel (recommended: without it psi relies on the measured line "
             "length)",
    )
    init.add_argument(
        "--fixed-end",
        metavar="X,Y",
        help="pixel near the clamped end, e.g. 812,455 (recommended; default: guessed per photo)",
    )
    init.add_argument(
        "--fixed-direction-deg",
        type=float,
        metavar="DEG",
        help="body: the direction in which the actuator leaves the clamp, on screen, deg "
             "counter-clockwise from +x (0 = right, 90 = up); psi is then the free end's tangent "
             "against it and does not depend on the base (recommended where the base is short, "
             "hidden or faint, as a translucent body's often is)",
    )
    init.add_argument(
        "--target",
        choices=("line", "body"),
        default="line",
        help="measure a drawn line (default) or the actuator's body",
    )
    init.add_argument(
        "--sealed-end-mm",
        type=float,
        help="body: length of the actuator's end that does not bend, from where its chamber ends "
             "to its tip (sealed end and cap), mm (recommended: without it a long sealed end "
             "reads |psi| high; without --mm-per-px it is scaled by the body's length against "
             "l0_mm + this)",
    )
    init.add_argument(
        "--body-width-mm",
        type=float,
        help="body: its width as the camera sees it, mm (with --mm-per-px a photo whose body is "
             "read 20 %% wider or narrower is flagged: its shadow taken in, a faint side lost; "
             "leave it out for a body that swells under pressure)",
    )
    init.add_argument(
        "--free-end",
        choices=FREE_ENDS,
        default=None,
        help="body: capped (its end does not bend: a sealed end, a cap; the default) or bends (a "
             "cut strip that bends to its end, as a free bilayer strip)",
    )
    init.add_argument(
        "--exclude",
        action="append",
        metavar="X0,Y0,X1,Y1",
        help="a box of the photo to leave out (a clamp plate, a ruler, a label), corner to corner "
             "in pixels; repeat for several (a polygon: write it in photoset.yaml)",
    )
    init.add_argument(
        "--background",
        metavar="FILE",
        help="body: a photo of the empty scene in the folder (same camera, light and framing, "
             "no actuator; recommended for translucent bodies and busy scenes); with {actuator} "
             "in it (and * if need be), each actuator's own: '{actuator}/empty_*.JPG'",
    )
    init.add_argument(
        "--line-color",
        default=None,
        help="colour of the line or body: a name (black, white, grey, red, orange, yellow, green, "
             "cyan, blue, purple, magenta), 'h,s,v-h,s,v', or several joined by ';' (default: "
             "black for a line, none for a body)",
    )
    init.add_argument(
        "--positive-turn",
        choices=POSITIVE_TURNS,
        default="ccw",
        help="turning direction on screen, fixed end to free end, that counts as positive psi "
             "(default ccw)",
    )
    init.add_argument("--overwrite", action="store_true", help="replace an existing manifest.csv")
    check = sub.add_parser(
        "check",
        help="validate a photo set and list every bad row with its fix",
        description="Validate manifest.csv, photoset.yaml and every image (decoded with OpenCV). "
                    "Exit 1 if anything is wrong.",
    )
    check.add_argument("folder", metavar="DIR", help="photo-set folder")
    check.add_argument(
        "--no-decode", action="store_true", help="only check that images exist (faster)"
    )
    calibrate = sub.add_parser(
        "calibrate",
        help="compute the camera calibration from the set's checkerboard photo(s) and store it "
             "(calibration.json)",
        description="For every calibration the photo set uses (photoset.yaml 'calibration: {board: "
                    "..., square_mm: ..., "
        "inner_corners: [columns, rows]}' or a manifest column): find the board, fit the lens and "
        "the plane, print "
        "the reprojection error in px and mm and store the result in DIR/calibration.json, which "
        "measuring then reads. "
        "Exit 1 if the set names no calibration, 2 if one cannot be computed (the board photo "
        "and the fix are named).",
    )
    calibrate.add_argument("folder", metavar="DIR", help="photo-set folder")
    calibrate.add_argument(
        "--max-error-px",
        type=float,
        default=None,
        help="warn above this reprojection error, px (default 1; rows using such a calibration are "
             "flagged when measured)",
    )
    preview = sub.add_parser(
        "preview",
        help="write one contact sheet showing what the settings select and measure: the first, "
             "the highest-pressure and the last photo of every ramp",
        description="For the first, the highest-pressure and the last photo of every ramp: the "
                    "photo with the selection tinted, roi/exclude, "
        "candidates, the chosen line or body centre line, the fixed end, the directions psi "
        "is measured between and psi, beside the selection mask and (for a body) its two ends "
        "enlarged.",
    )
    preview.add_argument("folder", metavar="DIR", help="photo-set folder")
    preview.add_argument(
        "--out",
        help="sheet to write, .jpg or .png (default: <DIR name>_preview.jpg in the current folder)",
    )
    preview.add_argument(
        "--all", action="store_true",
        help="every photo, not only three of each ramp (of a video set: the 24 frames of each "
             "video that --overlays draws)",
    )
    preview.add_argument(
        "--image", action="append", default=[], metavar="NAME",
        help="only this photo, named as in manifest.csv (e.g. trial1/IMG_0017.JPG: a flagged "
             "row's); repeatable",
    )
    preview.add_argument(
        "--frame", action="append", default=[], type=int, metavar="N",
        help="of a video set: only frame N of each video, numbered as angles.csv's frame column "
             "(from 0; a flagged frame's); repeatable. --all shows the 24 frames --overlays draws",
    )
    pick = sub.add_parser(
        "pick-color",
        help="print an HSV range (ready for photoset.yaml) for the colour around a pixel",
        description="Sample the colour around X,Y and print a line_color value that selects it "
                    "(red's hue wrap handled).",
    )
    pick.add_argument("image", metavar="IMAGE", help="a photo")
    pick.add_argument(
        "--at", required=True, metavar="X,Y", help="pixel (x right, y down) on the line or body"
    )
    pick.add_argument(
        "--radius", type=float, default=4.0, help="radius of the sampled disc, px (default 4)"
    )


def _xy(text: str, option: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise UserInputError(
            f"{option} {text!r}: write two pixel numbers as X,Y, e.g. 812,455"
        ) from None
    return x, y


def _box(text: str, option: str) -> tuple[float, float, float, float]:
    try:
        x0, y0, x1, y1 = (float(v) for v in text.split(","))
    except ValueError:
        raise UserInputError(
            f"{option} {text!r}: write a box's two corners in pixels as X0,Y0,X1,Y1, e.g. "
            "0,700,720,1440"
        ) from None
    return x0, y0, x1, y1


def run(args: argparse.Namespace) -> int:
    """Run ``photoset init``, ``check``, ``preview`` or ``pick-color``."""
    if args.photoset_command == "init":
        return _init(args)
    if args.photoset_command == "preview":
        from pipeline.photoset import PREVIEW_SHEET_SUFFIX
        from pipeline.preview import write_preview

        out = args.out or f"{Path(args.folder).resolve().name}{PREVIEW_SHEET_SUFFIX}.jpg"
        path, n = write_preview(
            args.folder, out, every=args.all, images=args.image, frames=args.frame
        )
        print(
            f"wrote {path}: {n} photo(s) or frame(s); green = ok, orange = flagged, tinted = what "
            "the settings select"
        )
        return 0
    if args.photoset_command == "pick-color":
        return _pick(args)
    if args.photoset_command == "calibrate":
        return _calibrate(args)
    return _check(args)


def _calibrate(args: argparse.Namespace) -> int:
    from pipeline.measure.calibration import MAX_RMS_PX, Calibration, write_store

    limit = MAX_RMS_PX if args.max_error_px is None else args.max_error_px
    # a folder-wide calibration that fails refuses the set, naming the file
    ps = photoset.load_photoset(args.folder)
    used: dict[tuple[tuple[str, ...], float, tuple[int, int]], tuple[Calibration, list[int]]] = {}
    for line, row in zip(ps.manifest["manifest_line"], ps.rows):
        if row is not None and row.calibration is not None:
            used.setdefault(row.calibration.key, (row.calibration, []))[1].append(int(line))
    failed = [p for p in ps.problems if "calibration" in p.message]
    for p in failed:
        print(f"  {p}", file=sys.stderr)
    if not used:
        if not failed:
            print(
                f"{args.folder}: no calibration in {photoset.SETTINGS} or the manifest (fix: add "
                "'calibration: "
                "{board: board.jpg, square_mm: 25, inner_corners: [9, 6]}' naming a photo of a "
                "checkerboard "
                "lying where the actuator lies)",
                file=sys.stderr,
            )
        return 1
    path = write_store(args.folder, [c for c, _ in used.values()])
    for cal, lines in used.values():
        plane = cal.plane
        assert plane is not None  # a row's calibration is resolved (computed or read) on loading
        boards = ", ".join(Path(b).name for b in cal.boards)
        f = plane.camera_matrix[0]
        print(
            f"{boards}: {cal.board_size}, {cal.square_mm:g} mm squares; {plane.views} photo(s), "
            f"{plane.corners} corners; "
            f"{len(lines)} row(s)"
        )
        print(
            f"  reprojection error {plane.rms_px:.3f} px, {plane.rms_mm:.4f} mm on the plane; "
            f"{plane.mm_per_px:.4f} mm per px at the board centre; focal {f:.0f} px, k1 "
            f"{plane.k1:+.4f}"
            + (f", k2 {plane.dist_coeffs[1]:+.4f}" if plane.views >= 3 else "")
        )
        if plane.rms_px > limit:
            print(
                f"  warning: reprojection error above {limit:g} px: the rows using it are flagged "
                "(fix: re-take the board "
                "photo flat, sharp and evenly lit, check square_mm and inner_corners, or add board "
                "photos in other poses)"
            )
    print(f"stored {len(used)} calibration(s) in {path}")
    return 1 if failed else 0


def _own_backgrounds(folder: str, pattern: str, df: pd.DataFrame) -> pd.DataFrame:
    """The manifest ``df`` written again with each actuator's own empty scene (``pattern`` with
    ``{actuator}``) in a ``background`` column (customer 36 could give ``--background`` one file
    for the whole set)."""
    found = photoset_init.backgrounds_by_actuator(
        folder, pattern, sorted(df["actuator"].astype(str).unique())
    )
    df = df.assign(background=df["actuator"].astype(str).map(found))
    photoset.write_manifest(folder, df)
    print("background: " + ", ".join(f"{a} {f}" for a, f in found.items()))
    return df


def _init(args: argparse.Namespace) -> int:
    defaults = {k: getattr(args, k) for k in RAMP_KEYS if getattr(args, k)}
    settings: dict[str, object] = {"l0_mm": args.l0_mm, "positive_turn": args.positive_turn}
    if args.mm_per_px is not None:  # without a ruler the key is left out, not written empty
        settings["mm_per_px"] = args.mm_per_px
    if args.target != "line":
        settings["target"] = args.target
    if args.line_color is not None or args.target == "line":
        settings["line_color"] = args.line_color or "black"
    if args.fixed_end:
        settings["fixed_end"] = list(_xy(args.fixed_end, "--fixed-end"))
    if args.fixed_direction_deg is not None:
        settings["fixed_direction_deg"] = args.fixed_direction_deg
    if args.sealed_end_mm is not None:
        settings["sealed_end_mm"] = args.sealed_end_mm
    if args.body_width_mm is not None:
        settings["body_width_mm"] = args.body_width_mm
    if args.free_end is not None:
        settings["free_end"] = args.free_end
    if args.exclude:
        settings["exclude"] = [list(_box(b, "--exclude")) for b in args.exclude]
    per_actuator = args.background is not None and "{actuator}" in args.background
    if args.background is not None and not per_actuator:
        if not (Path(args.folder) / args.background).is_file():
            raise UserInputError(
                f"--background {args.background}: no such file in {args.folder}; put the photo "
                "of the empty scene in the photo-set folder and give its name"
            )
        settings["background"] = args.background
    kept = (Path(args.folder) / photoset.SETTINGS).is_file()  # never overwritten: the user's
    if args.pressure_log is not None and photoset_init.names_videos(args.folder, args.pattern):
        if args.log_time_at is not None:
            raise UserInputError(
                "--log-time-at is for photos; a video's clock is placed on its log with "
                "--clock-offset-s (the log's time at its first frame)"
            )
        df = photoset_init.init_video_photoset(
            args.folder,
            args.pattern,
            args.pressure_log,
            clock_offset_s=args.clock_offset_s,
            fps=args.fps,
            defaults=defaults,
            settings=settings,
            overwrite=args.overwrite,
        )
        if per_actuator:
            df = _own_backgrounds(args.folder, args.background, df)
        trials = ", ".join(f"{r.video} trial {r.trial}" for r in df.itertuples())
        print(f"wrote {args.folder}/{photoset.MANIFEST}: {len(df)} video(s): {trials}")
        _print_next(args, kept)
        return 0
    if args.fps is not None:
        raise UserInputError(
            "--fps is for videos (or frames cut from one, --pattern 'frame_%04d.jpg') with their "
            f"--pressure-log; --pattern {args.pattern!r} names photos"
        )
    for option, value in (("--clock-offset-s", args.clock_offset_s),
                          ("--log-time-at", args.log_time_at)):
        if value is not None and args.pressure_log is None:
            raise UserInputError(f"{option} places photos on a pressure log: give --pressure-log "
                                 "too")
    if args.pressure_log is not None and args.pressures_kpa is not None:
        raise UserInputError("--pressure-log and --pressures-kpa both give the photos' "
                             "pressures: give one of them")
    if args.pressure_log is not None:
        return _init_logged(args, defaults, settings, per_actuator, kept)
    df = photoset_init.init_photoset(
        args.folder,
        args.pattern,
        defaults=defaults,
        settings=settings,
        overwrite=args.overwrite,
        leave_out=_own_empty_scenes(args, per_actuator),
        pressures_kpa=(
            None
            if args.pressures_kpa is None
            else photoset_init.pressure_specs(args.pressures_kpa)
        ),
    )
    if per_actuator:
        df = _own_backgrounds(args.folder, args.background, df)
    _print_written(args, df, kept)
    return 0


def _own_empty_scenes(args: argparse.Namespace, per_actuator: bool) -> list[str]:
    """Each actuator's photo of the empty scene (``--background`` with ``{actuator}``)."""
    if not per_actuator:
        return []
    return [
        p.relative_to(args.folder).as_posix()
        for p in Path(args.folder).glob(args.background.replace("{actuator}", "*"))
    ]


def _init_logged(
    args: argparse.Namespace,
    defaults: dict[str, Any],
    settings: dict[str, object],
    per_actuator: bool,
    kept: bool,
) -> int:
    """``init --pressure-log`` on photos: their pressures read from the log at their EXIF
    times, and what the user should check."""
    photo = log_time = None
    if args.log_time_at is not None:
        photo, sep, log_time = args.log_time_at.partition("=")
        if not (sep and photo.strip() and log_time.strip()):
            raise UserInputError(
                f"--log-time-at {args.log_time_at!r}: give PHOTO=TIME, the log's time when that "
                "photo was taken (IMG_0001.JPG=14:00:10.1)"
            )
        photo, log_time = photo.strip(), log_time.strip()
    df, placement = photoset_init.init_logged_photoset(
        args.folder,
        args.pattern,
        args.pressure_log,
        ClockSync(offset_s=args.clock_offset_s, photo=photo, log_time=log_time),
        defaults=defaults,
        settings=settings,
        overwrite=args.overwrite,
        leave_out=_own_empty_scenes(args, per_actuator),
    )
    if per_actuator:
        df = _own_backgrounds(args.folder, args.background, df)
    print(f"pressures read from {args.pressure_log} at the photos' EXIF times:")
    for note in placement.notes:
        print(f"  {note}")
    warnings = list(placement.warnings)
    if photo and photo in set(df["image"]):
        warnings.append(
            f"{photo}, named by --log-time-at, is one of the ramps' photos and is measured as "
            f"one: if it shows the logger's clock, move it out of the set's folder and give its "
            f"path from there (../{Path(photo).name})"
        )
    for line in warnings:
        print(line if line.startswith("  ") else f"warning: {line}", file=sys.stderr)
    _print_written(args, df, kept, (*placement.left_out, *([photo] if photo else [])))
    return 0


def _print_written(
    args: argparse.Namespace, df: pd.DataFrame, kept: bool, left_out: tuple[str, ...] = ()
) -> None:
    """Say what ``init`` wrote: the photos, each ramp, the photos it left out, what next."""
    n_up = int((df["direction"] == "up").sum())
    print(
        f"wrote {args.folder}/{photoset.MANIFEST}: {len(df)} photos ({n_up} up, {len(df) - n_up} "
        "down)"
    )
    for line in photoset_init.ramp_lines(df):
        print(f"  {line}")
    left = [
        name
        for name in photoset.unlisted_photos(Path(args.folder), df["image"], "/" in args.pattern)
        if name not in left_out
    ]
    if left:
        print(
            f"warning: {len(left)} photo(s) do not match the pattern and are not in the manifest: "
            + ", ".join(repr(n) for n in left[:5])
            + (", ..." if len(left) > 5 else "")
            + " (rename them to the pattern and run init again with --overwrite, or add their rows "
            "by hand; leave out an empty-scene or calibration photo)",
            file=sys.stderr,
        )
    _print_next(args, kept)


def _print_next(args: argparse.Namespace, kept: bool) -> None:
    """Say what ``init`` did with ``photoset.yaml`` and what to run next."""
    if kept:
        print(
            f"kept the existing {args.folder}/{photoset.SETTINGS} as it is (the setting options "
            "were not written into it): edit it, or delete it and run init again"
        )
        return
    print(
        f"wrote {args.folder}/{photoset.SETTINGS}: "
        + ("next: set l0_mm in it, then run" if args.l0_mm is None else "next: run")
        + f" 'python -m pipeline photoset check {args.folder}', then 'photoset preview'"
    )


def _pick(args: argparse.Namespace) -> int:
    from pipeline.measure.colors import color_mask, pick_color
    from pipeline.measure.formats import read_image

    img = read_image(args.image)
    if img is None:
        raise UserInputError(f"{args.image}: cannot be read as an image")
    x, y = _xy(args.at, "--at")
    spec = pick_color(img, x, y, args.radius)
    share = float(color_mask(img, spec).mean())
    print(f'line_color: "{spec.text}"')
    print(f"# {spec.describe()}; selects {100 * share:.1f}% of {Path(args.image).name}"
          + ("; that is a lot: pick on a purer spot or add an roi, or, for a body the colour "
             "of its backdrop, leave line_color out (target: body tells it from the backdrop)"
             if share > 0.3 else ""))
    return 0


def _check(args: argparse.Namespace) -> int:
    from pipeline.photoset_check import check_photoset

    problems = check_photoset(args.folder, decode_images=not args.no_decode, warnings=True)
    errors = [p for p in problems if not p.warning]
    try:  # an unreadable manifest is one of the problems listed
        manifest: pd.DataFrame | None = photoset.read_manifest(args.folder)
    except UserInputError:
        manifest = None
    video = manifest is not None and photoset.is_video_manifest(manifest)
    if not errors and not args.no_decode and not video:  # previews read photos, not videos
        from pipeline.preview import empty_first_photos

        for r in empty_first_photos(args.folder).itertuples():
            problems.append(
                photoset.Problem(
                    str(Path(args.folder) / photoset.MANIFEST),
                    r.manifest_line,
                    f"the first photo of its ramp ({r.image}) shows nothing that {r.what}",
                    "check line_color / background / roi with 'python -m pipeline photoset "
                    f"preview {args.folder}'",
                    warning=True,
                )
            )
    for line in photoset.problem_lines(problems):
        print(f"  {line}", file=sys.stderr)
    if errors:
        print(f"{args.folder}: {len(errors)} problem(s)", file=sys.stderr)
        return 1
    n = 0 if manifest is None else len(manifest)
    warn = len(problems) - len(errors)
    print(
        f"{args.folder}: OK ({n} "
        f"{'videos' if video else 'photos'}{f', {warn} warning(s)' if warn else ''})"
    )
    if video:
        from pipeline.video.clips import resolve_clips

        for clip in resolve_clips(photoset.load_photoset(args.folder)):
            print(f"  {clip.describe()}")
    return 0
