"""Bending moments of axial stress (Eq. 12) and of pressure on the end cap (Eq. 13)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pipeline.model.geometry import (
    BAD_STRETCH,
    OK,
    Section,
    axial_stretch_base,
    gauss_nodes,
    rest_heights,
    wall_coordinates,
)
from pipeline.model.materials import Material
from pipeline.model.ogden import axial_stress_mpa
from pipeline.model.options import ModelOptions

FloatArray = NDArray[np.float64]


def stress_moment_nmm(
    mat: Material, psi: FloatArray, sec: Section, l0: float, opts: ModelOptions
) -> tuple[FloatArray, FloatArray]:
    """Eq. 12: moment M_sigma of the axial stress about the inextensible layer, in N mm.

    The base (width 2 (a0 + t0), stretch of Eq. 1, lambda_2 = 1) plus the deformed wall (stretches
    of Eqs. 2-3 on the deformed section, integrated over the undeformed tau in [0, t0] and phi in
    [-pi/2, pi/2] by Gauss-Legendre, using the evenness in phi).  ``opts.jacobian="deformed"``
    multiplies the wall area element by (2 phi_m/pi)(t/t0), ``"deformed_angle"`` by (2 phi_m/pi)
    only (the integral over phi' without dtau'/dtau); ``opts.l0_factor`` keeps the printed l0
    prefactor with l0 in metres ("metres"), drops it ("none") or puts the FITTED number
    ``opts.eq12_scale`` in its place ("fitted_scale", resolved by the caller);
    ``opts.stress="nominal"`` divides the Cauchy stress by lambda_1;
    ``opts.base_width="one_side"`` drops the factor 2 of the base term; ``opts.wall_coords`` is
    passed to :func:`pipeline.model.geometry.wall_coordinates`.

    Returns
    -------
    moment_nmm : ndarray, shape (n,)
    reason : ndarray of int, shape (n,)
    """
    mu, alpha = mat.ogden_terms()
    beta, w_beta = gauss_nodes(opts.n_beta, 0.0, mat.b_mm)
    lam_b = axial_stretch_base(mat, beta[None, :], psi[:, None], l0)
    with np.errstate(all="ignore"):
        sig_b = axial_stress_mpa(lam_b, np.ones_like(lam_b), mu, alpha)
        if opts.stress == "nominal":
            sig_b = sig_b / lam_b
    width = (2.0 if opts.base_width == "two_sides" else 1.0) * (mat.a0_mm + mat.t0_mm)
    m_base = width * (sig_b * beta[None, :]) @ w_beta

    tau, w_tau = gauss_nodes(opts.n_tau, 0.0, mat.t0_mm)
    phi, w_phi = gauss_nodes(opts.n_phi, 0.0, 0.5 * math.pi)
    phi_m = sec.phi_m[:, None, None]
    r_def, _, height = wall_coordinates(mat, sec, tau, phi, opts)  # a + tau', phi', height
    h0 = rest_heights(mat, tau[:, None], phi[None, :])[None]
    lam1 = (l0 - height * psi[:, None, None]) / (l0 - h0 * mat.psi0_rad)
    lam2 = 2.0 * r_def * phi_m / ((mat.a0_mm + tau[None, :, None]) * math.pi)
    bad = ~((lam1 > 0) & (lam2 > 0)).all(axis=(1, 2)) | ~(lam_b > 0).all(axis=1)
    with np.errstate(all="ignore"):
        sig = axial_stress_mpa(lam1, lam2, mu, alpha)
        if opts.stress == "nominal":
            sig = sig / lam1
    integrand = sig * height * r_def
    m_wall = 2.0 * np.einsum("nij,i,j->n", integrand, w_tau, w_phi)
    if opts.jacobian == "deformed":
        m_wall = m_wall * (2.0 * sec.phi_m / math.pi) * (sec.t / mat.t0_mm)
    elif opts.jacobian == "deformed_angle":
        m_wall = m_wall * (2.0 * sec.phi_m / math.pi)
    moment = m_base + m_wall
    if opts.l0_factor == "metres":
        moment = moment * (l0 / 1000.0)
    elif opts.l0_factor == "fitted_scale":
        moment = moment * opts.eq12_scale
    reason = np.where((sec.reason == OK) & bad, BAD_STRETCH, sec.reason)
    return np.where(reason == OK, moment, np.nan), reason


def pressure_area_mm3(mat: Material, sec: Section, opts: ModelOptions) -> FloatArray:
    """Eq. 13 divided by P: first moment of the pressurised end-cap area about the layer (mm^3).

    ``"half_disc"`` (as printed): (4 a^3 + 3 pi a^2 (b + q))/6.  ``"segment"``: the chamber
    actually bounded by the arc and the base plane, (b + q) a^2 (phi_m - sin cos) + 2/3 a^3 sin^3.
    Both equal the undeformed half disc at rest.
    """
    a, q = sec.a, sec.q
    if opts.pressure_area == "segment":
        s, c = np.sin(sec.phi_m), np.cos(sec.phi_m)
        return (mat.b_mm + q) * a**2 * (sec.phi_m - s * c) + (2.0 / 3.0) * a**3 * s**3
    return (4.0 * a**3 + 3.0 * math.pi * a**2 * (mat.b_mm + q)) / 6.0


def wall_area_mm2(mat: Material, sec: Section, opts: ModelOptions) -> FloatArray:
    """Area the Eq. 12 wall element integrates to, per angle (mm^2): a check of each reading.

    The integral of (a + tau') times the ``jacobian`` factor over tau in [0, t0] and phi in
    [-pi/2, pi/2].  Only ``jacobian="deformed"`` gives A0 (the incompressible wall area of Eq. 6)
    at every angle; ``"none"`` and ``"deformed_angle"`` do not (``deformed_angle``: A0 t0 / t).
    """
    tau, w_tau = gauss_nodes(opts.n_tau, 0.0, mat.t0_mm)
    phi, w_phi = gauss_nodes(opts.n_phi, 0.0, 0.5 * math.pi)
    r_def, _, _ = wall_coordinates(mat, sec, tau, phi, opts)
    r_def = np.broadcast_to(r_def, (sec.a.size, tau.size, phi.size))
    area = 2.0 * np.einsum("nij,i,j->n", r_def, w_tau, w_phi)
    if opts.jacobian == "deformed":
        area = area * (2.0 * sec.phi_m / math.pi) * (sec.t / mat.t0_mm)
    elif opts.jacobian == "deformed_angle":
        area = area * (2.0 * sec.phi_m / math.pi)
    return area
