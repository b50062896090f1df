"""``python -m pipeline bench WHAT [options]``: run one benchmark (``--help`` after WHAT lists its
options).

Only the module of the benchmark being run is imported.
"""

from __future__ import annotations

import argparse
import importlib

#: what -> (module with ``main(argv)``, one-line help)
BENCHES: dict[str, tuple[str, str]] = {
    "study": (
        "pipeline.bench.study",
        (
            "speed/accuracy and stability study of the angle methods and the model "
            "(tables and charts for the report; --grid default|full)"
        ),
    ),
    "measure": (
        "pipeline.bench.measure",
        (
            "angle measurement: accuracy per method, speed against imread and a "
            "skeleton baseline, --jobs scaling"
        ),
    ),
    "calibration": (
        "pipeline.bench.calibration",
        (
            "measuring on a calibrated plane: accuracy against the physical "
            "psi and cost, tilted cameras and lens distortion"
        ),
    ),
    "realscenes": (
        "pipeline.bench.realscenes",
        "body mode on the committed real strips and on synthetic analogues of real scenes",
    ),
    "ramps": (
        "pipeline.bench.ramps",
        (
            "rendered body ramp sets measured as a user does, with and without the second "
            "look against the ramp's own photos"
        ),
    ),
    "video": (
        "pipeline.bench.video",
        "a rendered video measured end to end: frames per second, memory, accuracy",
    ),
    "model": ("pipeline.bench.model", "model time and error against the quadrature grid size"),
    "synth": (
        "pipeline.bench.synth",
        "rendering: the default synthetic campaign (images/s), or one photo per scene",
    ),
    "rig": (
        "pipeline.bench.rig",
        "rig software against the emulator: round trips, per-photo loop overhead",
    ),
    "force": (
        "pipeline.bench.force",
        "eccentricity accuracy of the ellipse fit on points and rendered photos",
    ),
    "report": (
        "pipeline.bench.report",
        "aggregate -> compare -> report on synthetic angles tables",
    ),
    "campaign": (
        "pipeline.bench.campaign",
        "after a run: the error of every dataset that has ground truth",
    ),
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``python -m pipeline bench``: which benchmark, then its own options."""
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    width = max(map(len, BENCHES))
    parser.epilog = "benchmarks:\n" + "\n".join(
        f"  {name:<{width}}  {text}" for name, (_, text) in BENCHES.items()
    )
    parser.add_argument(
        "what", choices=list(BENCHES), metavar="WHAT", help="the benchmark (listed below)"
    )
    parser.add_argument("options", nargs=argparse.REMAINDER,
                        help="its options (python -m pipeline bench WHAT --help)")


def run(args: argparse.Namespace) -> int:
    """Run the benchmark named by ``args.what`` with its options; its exit code."""
    module = importlib.import_module(BENCHES[args.what][0])
    return int(module.main(args.options) or 0)
