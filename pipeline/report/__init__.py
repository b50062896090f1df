"""The PDF report: summary, Fig. 6-style hysteresis plots, Fig. 5-style photo strips, comparison table.

Public API
----------
build_report(inputs: ReportInputs, out) -> ReportResult
ReportInputs, Dataset                 (what the report is built from)
load_report_data(inputs) -> ReportData

Bench and force pages come from ``pipeline.bench.pages.figures(dir)`` and
``pipeline.force.pages.figures(dir)`` when those modules and folders exist.
"""

from pipeline.report.build import ReportResult, build_report
from pipeline.report.data import Dataset, ReportData, ReportInputs, load_report_data

__all__ = ["Dataset", "ReportData", "ReportInputs", "ReportResult", "build_report", "load_report_data"]
