"""The readings of the ambiguous equations of the paper, as one frozen options record.

Every public model function accepts these as keyword ``**options``; the defaults are the reading
chosen by calibration (see ``docs/model.md`` and ``python -m pipeline model calibrate``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

from pipeline.errors import UserInputError

#: allowed values of the categorical options (the defaults are those of :class:`ModelOptions`,
#: chosen by the selection protocol of :mod:`pipeline.model.calibrate`)
CHOICES: dict[str, tuple[str, ...]] = {
    # Eq. 5: "as_printed" A0/(2 sin(phi_m) t) - t/2 = a0/sin(phi_m) (no root: sin(phi_m) > 1);
    # "arc_length" A0/(2 phi_m t) - t/2 = a0/sin(phi_m), i.e. Eq. 6 (area conserved) with the arc
    # meeting the undeformed chamber width, a sin(phi_m) = a0; exact at rest (phi_m = pi/2).
    "eq5": ("arc_length", "as_printed"),
    # thickness scaling for materials with k_t:  "as_printed"  t * k_t (1 - |psi-psi0|/psi0);
    # "one_minus"  t * (1 - k_t |psi-psi0|/psi0);  "none"  no scaling.
    "kt_scaling": ("one_minus", "as_printed", "none"),
    # Eq. 12 wall area element: "none" (as printed, (a+tau') dphi dtau); "deformed_angle"
    # (integrated over the deformed angle phi': (a+tau') dphi' dtau = (a+tau') (2 phi_m/pi) dphi
    # dtau, without dtau'/dtau); "deformed" (both: (a+tau') dphi' dtau' = (a+tau') (2 phi_m/pi)
    # (t/t0) dphi dtau, the area-consistent element).
    "jacobian": ("none", "deformed_angle", "deformed"),
    # Eq. 12 l0 prefactor, absent from Eq. 13 (so P is dimensionally a pressure times a length):
    # "metres" keeps it as printed with l0 in metres (SI), i.e. scales P by l0/1 m;
    # "none" drops it (dimensionally consistent, P about 3x the paper's model);
    # "fitted_scale" drops l0 and puts a dimensionless number ``eq12_scale`` in its place, FITTED
    # to the paper's own two model results (a fit, not a derivation: see docs/model.md).
    "l0_factor": ("metres", "none", "fitted_scale"),
    # Eq. 13 pressure area: "half_disc" as printed; "segment" the real chamber (circle of radius a
    # cut by the base plane, = half disc at rest).
    "pressure_area": ("half_disc", "segment"),
    # Eq. 4 integrand lambda(phi, tau) (Eq. 4 integrates over tau only and leaves phi open):
    # "crown" at phi = 0, "mean" averaged over phi.
    "thickness_phi": ("crown", "mean"),
    # Eq. 4 pass: "first" evaluates lambda_{phi,tau} on the undeformed section (as printed);
    # "recalculated" recomputes Eq. 4 once more with the axial stretch of the deformed section
    # (the paper's recalculation step applied to the thickness too; lambda_2 = 1 as in "x 1").
    "thickness_pass": ("first", "recalculated"),
    # Eqs. 9-12 stress: "cauchy" as printed; "nominal" Cauchy / lambda_1 (force per undeformed
    # area, the first Piola-Kirchhoff stress).
    "stress": ("cauchy", "nominal"),
    # Eq. 12 base width: "two_sides" 2 (a0 + t0) as printed; "one_side" (a0 + t0) (no factor 2).
    "base_width": ("two_sides", "one_side"),
    # Eq. 12 wall coordinates: "scaled" tau' = tau t/t0, phi' = phi 2 phi_m/pi as defined in the
    # text; "unscaled" tau' = tau, phi' = phi (contradicts those definitions: diagnostic only).
    "wall_coords": ("scaled", "unscaled"),
}

#: the reading of each option that is the printed text itself ("as printed"; for l0_factor the
#: printed l0 in SI units); the selection protocol counts departures from these.  Options
#: missing here (thickness_phi) are left open by the text.
PRINTED: dict[str, str] = {
    "eq5": "as_printed",
    "kt_scaling": "as_printed",
    "jacobian": "none",
    "l0_factor": "metres",
    "pressure_area": "half_disc",
    "thickness_pass": "first",
    "stress": "cauchy",
    "base_width": "two_sides",
    "wall_coords": "scaled",
}

#: most negative and most positive angle the model accepts as a search bound (deg): the design's
#: range (a line turning more than once around is not an actuator state we can photograph)
PSI_LIMIT_DEG = 360.0


@dataclass(frozen=True)
class ModelOptions:
    """Options of the analytical model.

    The defaults are the reading chosen by the selection protocol printed by
    ``python -m pipeline model calibrate`` (docs/model.md): derived from the printed equations,
    no constant fitted to the paper's numbers; the one physical parameter the paper's two model
    results fix, l0, lives in the materials file.

    Attributes
    ----------
    eq5, kt_scaling, jacobian, l0_factor, pressure_area, thickness_phi : str
    thickness_pass, stress, base_width, wall_coords : str
        Readings of the ambiguous equations; see :data:`CHOICES`.
    eq12_scale : float or None
        Only with ``l0_factor="fitted_scale"``: the dimensionless number standing for Eq. 12's l0
        prefactor.  ``None`` (default) fits it to the paper's two model results for the other
        readings and the l0 in use (:func:`pipeline.model.fit_eq12_scale`); it is a fit either way.
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
        Most negative angle the inverse searches (deg), in [-360, psi0).
    unload_from_kpa : float or None
        Unloading branch only: start from the loading state reached at this peak pressure (kPa)
        instead of from ``psi_min_deg``; matters only where P(psi) has snap-through.
    """

    eq5: str = "arc_length"
    kt_scaling: str = "one_minus"
    jacobian: str = "deformed_angle"
    l0_factor: str = "metres"
    pressure_area: str = "half_disc"
    thickness_phi: str = "crown"
    thickness_pass: str = "first"
    stress: str = "cauchy"
    base_width: str = "two_sides"
    wall_coords: str = "scaled"
    eq12_scale: float | None = None
    l0_mm: float | None = None
    k_p: float | None = None
    n_tau: int = 4
    n_phi: int = 8
    n_beta: int = 3
    n_grid: int = 400
    psi_min_deg: float = -360.0
    unload_from_kpa: float | None = None


_NAMES = {f.name for f in fields(ModelOptions)}
_INTS = ("n_tau", "n_phi", "n_beta", "n_grid")
_POSITIVE_OR_NONE = ("eq12_scale", "l0_mm", "k_p")


def _number(key: str, value: Any) -> float:
    """``value`` as a finite float, or a UserInputError naming the option (strings refused)."""
    if isinstance(value, (str, bytes, bool)):
        raise UserInputError(
            f"model options: {key} must be a number, got the text {value!r}; pass a number"
        )
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise UserInputError(f"model options: {key} must be a number, got {value!r}") from None
    if not math.isfinite(out):
        raise UserInputError(
            f"model options: {key} must be finite, got {value!r}; pass a finite number"
        )
    return out


def _check(key: str, value: Any) -> Any:
    """Validated value of one option (raises :class:`UserInputError` with the fix)."""
    if key in CHOICES:
        if value not in CHOICES[key]:
            raise UserInputError(f"model options: {key}={value!r} is not one of {CHOICES[key]}")
        return value
    if key in _INTS:
        x = _number(key, value)
        if int(x) != x or x < 2:
            raise UserInputError(f"model options: {key} must be an integer >= 2, got {value!r}")
        return int(x)
    if value is None and (key in _POSITIVE_OR_NONE or key == "unload_from_kpa"):
        return None
    x = _number(key, value)
    if key in _POSITIVE_OR_NONE and not x > 0:
        raise UserInputError(f"model options: {key} must be > 0, got {value!r}")
    if key == "unload_from_kpa" and not x >= 0:
        raise UserInputError(f"model options: unload_from_kpa must be >= 0 kPa, got {value!r}")
    if key == "psi_min_deg" and not -PSI_LIMIT_DEG <= x < PSI_LIMIT_DEG:
        raise UserInputError(
            f"model options: psi_min_deg = {value!r} deg is outside [-{PSI_LIMIT_DEG:g}, "
            f"{PSI_LIMIT_DEG:g}); pass the most negative angle to search, e.g. -360 (the default) "
            "or -210 (-psi0)"
        )
    return x


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
        For an unknown option name or value: a reading not in :data:`CHOICES`, a text, NaN or
        infinite number, a non-positive ``eq12_scale``/``l0_mm``/``k_p``, ``psi_min_deg``
        outside [-360, 360).

    Examples
    --------
    >>> make_options(eq12_scale=float("inf"))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pipeline.errors.UserInputError: model options: eq12_scale must be finite, got inf; ...
    """
    opts = base or ModelOptions()
    if not options:
        return opts
    unknown = set(options) - _NAMES
    if unknown:
        raise UserInputError(
            f"model options: unknown option(s) {sorted(unknown)}; valid: {sorted(_NAMES)}"
        )
    return replace(opts, **{key: _check(key, value) for key, value in options.items()})
