"""The PDF report an advisor reads: a one-minute summary, Fig. 6-style plots, photo strips,
the comparison with the paper, the angle-method bench, blocked force and grasping, provenance.

Modules (import what you need; this package import stays light)
---------------------------------------------------------------
build      ``build_report(inputs, out) -> ReportResult``: every page in order, written atomically
data       ``ReportInputs``, ``Dataset``, ``load_report_data(inputs) -> ReportData``
summary    page 1 (results per material beside the paper, data quality, real or synthetic)
pages      the overview, one page per material and the comparison page
strip      the Fig. 5-style photo strip of one ramp
provenance the last page: software, config and the sha256 of every input
reasons    flag and failure reasons in words
textcheck  the texts a page draws, with their extents (tests check overlaps and sizes)

The page style and typeset tables are in :mod:`pipeline.layout` (shared with the pages of the
study, force and video datasets, which this package draws through their ``figures``).
"""
