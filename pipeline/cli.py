"""Command-line interface: ``python -m pipeline SUBCOMMAND ...``.

Each subcommand lives in its own module, which exposes two functions::

    def add_arguments(parser: argparse.ArgumentParser) -> None: ...
    def run(args: argparse.Namespace) -> int: ...

Only the module of the subcommand being run is imported, so ``--help`` and small commands stay
fast (OpenCV and matplotlib are not loaded unless needed).
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import threading
from collections.abc import Sequence
from types import FrameType

from pipeline import __version__
from pipeline.errors import UserInputError

#: subcommand -> (module implementing it, one-line help)
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "photoset": (
        "pipeline.photoset_cli",
        "create (init) or validate (check) a photo set folder: manifest.csv + photoset.yaml",
    ),
    "synth": (
        "pipeline.synth.cli",
        "render a synthetic pressure-ramp photo set with exact ground truth",
    ),
    "synth-video": (
        "pipeline.synth.video_cli",
        "render a synthetic video photo set (video + pressure log) with exact truth",
    ),
    "acquire": (
        "pipeline.rig.acquire_cli",
        "run the pressure ramp on a rig (real or emulated) and photograph it",
    ),
    "rig": (
        "pipeline.rig.cli",
        "rig utilities: emulate the Pico over a pseudo-terminal, calibrate the regulator",
    ),
    "measure": (
        "pipeline.measure_cli",
        "measure the bending angle psi (deg) of every photo of a photo set",
    ),
    "aggregate": (
        "pipeline.aggregate_cli",
        "aggregate angles.csv into mean/sd hysteresis curves per pressure (kPa)",
    ),
    "continuous": (
        "pipeline.video.continuous_cli",
        "a video's loops, settling curves and step responses (s, deg, kPa)",
    ),
    "model": (
        "pipeline.model.cli",
        "analytical model of the paper: P(psi) curves, inverse, k_P calibration",
    ),
    "compare": (
        "pipeline.compare_cli",
        "compare measured hysteresis with the model: RMS (deg), crossings (kPa), k_P",
    ),
    "report": ("pipeline.report.cli", "write the PDF report from the results tables"),
    "bench": (
        "pipeline.bench.cli",
        (
            "benchmarks that print figures: the speed/accuracy study (bench study), measure, "
            "video, ..."
        ),
    ),
    "force": ("pipeline.force.cli", "blocked force, eccentricity and grasp-log analysis"),
}


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """Build the argument parser, importing only the module of ``command``.

    Parameters
    ----------
    command : str or None
        Subcommand whose arguments should be fully defined; ``None`` builds only the listing.

    Returns
    -------
    argparse.ArgumentParser
    """
    parser = argparse.ArgumentParser(
        prog="python -m pipeline",
        description=(
            "Characterise circular soft pneumatic actuators: acquire pressure ramps, measure the "
            "bending angle psi (degrees) from photos, aggregate hysteresis, compare with the "
            "analytical model and report.  Pressures are in kPa, angles in degrees, lengths in mm."
        ),
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="SUBCOMMAND")
    for name, (module_name, help_text) in SUBCOMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        if name == command:
            module = importlib.import_module(module_name)
            module.add_arguments(p)
            p.set_defaults(_run=module.run)
    return parser


def _terminated(signum: int, frame: FrameType | None) -> None:
    raise SystemExit(128 + signum)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the process exit code.

    SIGTERM (how Snakemake and cluster schedulers cancel a job) unwinds the command like Ctrl-C
    does, so half-written outputs are removed on the way out (exit status 143); Ctrl-C exits
    with 130 and one line instead of a traceback.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    command = next((a for a in argv if not a.startswith("-")), None)
    parser = build_parser(command if command in SUBCOMMANDS else None)
    args = parser.parse_args(argv)
    if getattr(args, "_run", None) is None:
        parser.print_help()
        return 0 if not argv else 2
    in_main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminated) if in_main else None
    try:
        return int(args._run(args) or 0)
    except UserInputError as exc:  # bad input: one clear message, no traceback
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into a reader that stopped (`| head`): no traceback
        # (customer 34); what is left to print goes nowhere, as Python's own docs advise
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141  # as a shell reports a command stopped by SIGPIPE
    except KeyboardInterrupt:
        print(f"{command}: interrupted", file=sys.stderr)
        return 130
    finally:
        if in_main:
            signal.signal(signal.SIGTERM, previous)
