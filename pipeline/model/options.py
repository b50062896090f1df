"""The readings of the ambiguous equations of the paper, as one frozen options record.

Every public model function accepts these as keyword ``**options``; the defaults are the reading
chosen by calibration (see ``docs/model.md`` and ``python -m pipeline model calibrate``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

from pipeline.errors import UserInputError

#: allowed values of the categorical options (first listed = meaning in the paper's own words)
CHOICES: dict[str, tuple[str, ...]] = {
    # Eq. 5: "as_printed" A0/(2 sin(phi_m) t) - t/2 = a0/sin(phi_m) (no root: sin(phi_m) > 1);
    # "arc_length" A0/(2 phi_m t) - t/2 = a0/sin(phi_m), i.e. Eq. 6 (area conserved) with the arc
    # meeting the undeformed chamber width, a sin(phi_m) = a0; exact at rest (phi_m = pi/2).
    "eq5": ("arc_length", "as_printed"),
    # thickness scaling for materials with k_t:  "as_printed"  t * k_t (1 - |psi-psi0|/psi0);
    # "one_minus"  t * (1 - k_t |psi-psi0|/psi0);  "none"  no scaling.
    "kt_scaling": ("one_minus", "as_printed", "none"),
    # Eq. 12 area element: "none" (as printed, (a+tau') dphi dtau) or "deformed"
    # ((a+tau') dphi' dtau' = (a+tau') (2 phi_m/pi)(t/t0) dphi dtau).
    "jacobian": ("none", "deformed"),
    # Eq. 12 l0 prefactor, absent from Eq. 13 (so P is dimensionally a pressure times a length):
    # "calibrated" drops l0 and puts the dimensionless number ``eq12_scale`` in its place, fitted
    # to the paper's own two model results (pipeline.model.calibrate.fit_eq12_scale);
    # "metres" keeps it as printed with l0 in metres (SI code), i.e. scales P by l0/1 m;
    # "none" drops it (dimensionally consistent, P about 3x the paper's model).
    "l0_factor": ("calibrated", "metres", "none"),
    # Eq. 13 pressure area: "half_disc" as printed; "segment" the real chamber (circle of radius a
    # cut by the base plane, = half disc at rest).
    "pressure_area": ("half_disc", "segment"),
    # Eq. 4 integrand lambda(phi, tau): "mean" averaged over phi, "crown" at phi = 0.
    "thickness_phi": ("mean", "crown"),
    # Eq. 4 pass: "first" evaluates lambda_{phi,tau} on the undeformed section (as printed);
    # "recalculated" recomputes Eq. 4 once more with the axial stretch of the deformed section
    # (the paper's recalculation step applied to the thickness too; lambda_2 = 1 as in "x 1").
    "thickness_pass": ("first", "recalculated"),
    # Eqs. 9-12 stress: "cauchy" as printed; "nominal" Cauchy / lambda_1 (force per undeformed
    # area, the first Piola-Kirchhoff stress).
    "stress": ("cauchy", "nominal"),
    # Eq. 12 base width: "two_sides" 2 (a0 + t0) as printed; "one_side" (a0 + t0) (factor 2 dropped).
    "base_width": ("two_sides", "one_side"),
    # Eq. 12 wall coordinates: "scaled" tau' = tau t/t0, phi' = phi 2 phi_m/pi as defined in the
    # text; "unscaled" tau' = tau, phi' = phi (contradicts those definitions: diagnostic only).
    "wall_coords": ("scaled", "unscaled"),
}


#: Eq. 12's l0 prefactor read as this dimensionless number (``l0_factor="calibrated"``): the
#: geometric-mean fit of the two model results the paper reports (SS50 straight at 674 kPa, SS40
#: at -psi0 at 378 kPa) with the default readings and l0 = 270 mm; reproduce it with
#: ``python -m pipeline model calibrate`` (docs/model.md).  Within 1 % of 1/pi.
EQ12_SCALE = 0.3214


@dataclass(frozen=True)
class ModelOptions:
    """Options of the analytical model.

    Attributes
    ----------
    eq5, kt_scaling, jacobian, l0_factor, pressure_area, thickness_phi : str
    thickness_pass, stress, base_width, wall_coords : str
        Readings of the ambiguous equations; see :data:`CHOICES`.
    eq12_scale : float
        Dimensionless factor standing for Eq. 12's l0 prefactor with ``l0_factor="calibrated"``.
        The default :data:`EQ12_SCALE` is ``fit_eq12_scale()`` for the default readings at the
        packaged l0 = 270 mm (a test keeps the two equal).
    l0_mm : float or None
        Override of the material's inextensible-layer length l0 (mm).
    k_p : float or None
        Override of the material's pressure scale k_P.
    n_tau, n_phi, n_beta : int
        Gauss-Legendre nodes over the wall thickness tau, the half section angle phi in
        [0, pi/2] (the integrands are even in phi) and the base coordinate beta.
    n_grid : int
        Angles of the grid the inverse brackets its roots on (psi_min_deg .. psi0).
    psi_min_deg : float
        Most negative angle the inverse searches (deg).
    unload_from_kpa : float or None
        Unloading branch only: start from the loading state reached at this peak pressure (kPa)
        instead of from ``psi_min_deg``; matters only where P(psi) has snap-through.
    """

    eq5: str = "arc_length"
    kt_scaling: str = "one_minus"
    jacobian: str = "none"
    l0_factor: str = "calibrated"
    pressure_area: str = "half_disc"
    thickness_phi: str = "mean"
    thickness_pass: str = "first"
    stress: str = "cauchy"
    base_width: str = "two_sides"
    wall_coords: str = "scaled"
    eq12_scale: float = EQ12_SCALE
    l0_mm: float | None = None
    k_p: float | None = None
    n_tau: int = 4
    n_phi: int = 8
    n_beta: int = 3
    n_grid: int = 400
    psi_min_deg: float = -360.0
    unload_from_kpa: float | None = None


_NAMES = {f.name for f in fields(ModelOptions)}


def make_options(base: ModelOptions | None = None, **options: Any) -> ModelOptions:
    """Validate keyword options and return a :class:`ModelOptions`.

    Parameters
    ----------
    base : ModelOptions, optional
        Starting point (defaults when omitted).
    **options
        Field overrides.

    Raises
    ------
    pipeline.errors.UserInputError
        For an unknown option name or value.
    """
    opts = base or ModelOptions()
    if not options:
        return opts
    unknown = set(options) - _NAMES
    if unknown:
        raise UserInputError(
            f"model options: unknown option(s) {sorted(unknown)}; valid: {sorted(_NAMES)}"
        )
    for key, value in options.items():
        if key in CHOICES and value not in CHOICES[key]:
            raise UserInputError(f"model options: {key}={value!r} is not one of {CHOICES[key]}")
        if key in ("n_tau", "n_phi", "n_beta", "n_grid") and (int(value) != value or value < 2):
            raise UserInputError(f"model options: {key} must be an integer >= 2, got {value!r}")
        if key == "unload_from_kpa" and value is not None and not float(value) >= 0:
            raise UserInputError(f"model options: unload_from_kpa must be >= 0 kPa, got {value!r}")
        if key == "eq12_scale" and not float(value) > 0:
            raise UserInputError(f"model options: eq12_scale must be > 0, got {value!r}")
        if key in ("l0_mm", "k_p") and value is not None and not float(value) > 0:
            raise UserInputError(f"model options: {key} must be > 0, got {value!r}")
    return replace(opts, **options)
