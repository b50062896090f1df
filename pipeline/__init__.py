"""Characterisation pipeline for circular soft pneumatic actuators.

Drives a pressure ramp (real rig or synthetic), measures the bending angle psi from each photo,
aggregates the increasing/decreasing-pressure hysteresis, compares it with the analytical model of
the paper and writes a PDF report.  Every stage is a plain function usable without Snakemake; the
command line is ``python -m pipeline --help``.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("circular-actuator-pipeline")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
