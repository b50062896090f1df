"""Blocked force, eccentricity and grasp logs (paper Sections II.C, III.B-C; Figs. 7A, 7B, 8B).

Modules (one job each)
----------------------
ellipse          ``fit_ellipse(points_px) -> EllipseFit``: direct (Fitzgibbon) fit, geometric
                 refinement on partial arcs, outlier trimming, arc coverage, e and its sd, flags
blocked          ``measure_blocked_image`` / ``measure_blocked_photoset`` -> eccentricity.csv
synth_blocked    ``render_blocked_photoset``: synthetic blocked-force sets with known e and force
aggregate_force  ``force_vs_pressure``, ``eccentricity_at_max_pressure`` (mean +- sd per material)
grasp            ``read_grasp_log``, ``heaviest_held`` (Fig. 8B data)
pages            ``figures(force_dir) -> list[Figure]`` for the PDF report (and ``grasp_figure``)
cli              ``python -m pipeline force synth|measure|aggregate|grasp|pages``

Modules are imported on demand (``from pipeline.force.ellipse import fit_ellipse``), so this
package import stays light.
"""
