"""The printed page every page builder shares: A4 geometry, fonts, colours, typeset text and tables.

Modules
-------
style      A4 pages, the footer band, fonts, one colour per material (``page``, ``text_page``,
           ``report_style``, ``material_colors``)
typeset    text and typeset tables placed in points (``Flow``, ``Table``, ``fmt``)

The report (:mod:`pipeline.report`) and the pages of the study, force and video datasets draw on
these, so each owns its pages while the PDF keeps one style.
"""
