"""Analytical model of the paper (Section II.B, Eqs. 1-13, Table I): P(psi), its inverse, k_P fits.

Public API
----------
pressure_kpa(material, psi_deg, **options) -> ndarray
psi_deg(material, pressure_kpa, branch="loading", **options) -> ndarray
fit_k_p(material, pressure_kpa, psi_deg) -> (k_p, (ci_low, ci_high))
load_materials(path=None) -> dict[str, Material]
model_curve(material, psi_deg=None, **options) -> DataFrame   (with the reason for every NaN)
snap_regions(material, **options) -> DataFrame                 (snap-through jumps)
anchor_table(**options) -> DataFrame                           (paper anchors: paper, ours, % off)
fit_l0(**options) -> float                                     (the l0 the two model results fix)
search_readings(keys) -> DataFrame, select_reading(df)         (the selection protocol)
fit_eq12_scale(**options) -> float                             (the fitted_scale option: a fit)

``options`` are the readings of the ambiguous equations and the quadrature sizes, see
:class:`ModelOptions` and ``docs/model.md``.  Material names: "DS20", "DS30", "SS40", "SS50".
"""

from pipeline.model.calibrate import (
    PROTOCOL,
    anchor_table,
    fit_eq12_scale,
    fit_k_p,
    fit_l0,
    search_readings,
    select_reading,
)
from pipeline.model.forward import model_curve, pressure_kpa
from pipeline.model.geometry import REASONS
from pipeline.model.inverse import psi_deg, snap_regions
from pipeline.model.materials import DEFAULT_MATERIALS_PATH, Material, load_materials
from pipeline.model.options import CHOICES, ModelOptions, make_options

MATERIAL_NAMES: tuple[str, ...] = ("DS20", "DS30", "SS40", "SS50")

__all__ = [
    "CHOICES",
    "DEFAULT_MATERIALS_PATH",
    "MATERIAL_NAMES",
    "PROTOCOL",
    "REASONS",
    "Material",
    "ModelOptions",
    "anchor_table",
    "fit_eq12_scale",
    "fit_k_p",
    "fit_l0",
    "load_materials",
    "make_options",
    "model_curve",
    "pressure_kpa",
    "psi_deg",
    "search_readings",
    "select_reading",
    "snap_regions",
]
