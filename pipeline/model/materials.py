"""Materials (paper Table I, k_P, k_t) and actuator geometry, loaded from a YAML data file.

The default file is ``pipeline/model/materials.yaml``; a user adds a silicone by writing their own
file with the same layout and passing its path (no code change).
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from pipeline.errors import UserInputError
from pipeline.fileio import read_user_text

#: the data file shipped with the package
DEFAULT_MATERIALS_PATH = Path(__file__).with_name("materials.yaml")

_GEOMETRY_KEYS = ("b_mm", "a0_mm", "t0_mm", "psi0_deg", "l0_mm")


@dataclass(frozen=True)
class Material:
    """One silicone actuator: Ogden parameters, fitted scale factors and geometry.

    Attributes
    ----------
    name : str
        Material key, e.g. ``"DS20"``.
    mu_mpa, alpha : tuple of float
        Ogden coefficients of Eq. 8 (paper convention, moduli in MPa).  Kept exactly as given:
        terms are never merged here (see :meth:`ogden_terms`).
    k_p : float
        Pressure scale factor k_P fitted by the paper.
    k_t : float or None
        Wall-thickness scale constant k_t (Dragon Skin only); ``None`` means no scaling.
    b_mm, a0_mm, t0_mm : float
        Base thickness b, inner radius a0 and wall thickness t0 of the undeformed section.
    psi0_deg : float
        Rest bending angle psi0 (deg).
    l0_mm : float
        Length of the inextensible layer l0 (mm).
    description : str
        Free text (source of the parameters).
    """

    name: str
    mu_mpa: tuple[float, ...]
    alpha: tuple[float, ...]
    k_p: float
    k_t: float | None
    b_mm: float
    a0_mm: float
    t0_mm: float
    psi0_deg: float
    l0_mm: float
    description: str = ""

    @property
    def psi0_rad(self) -> float:
        """Rest bending angle psi0 in radians."""
        return math.radians(self.psi0_deg)

    @property
    def height_mm(self) -> float:
        """Height b + a0 + t0 of the section above the inextensible layer (mm)."""
        return self.b_mm + self.a0_mm + self.t0_mm

    @property
    def min_l0_mm(self) -> float:
        """Shortest l0 the section allows: the top fibre's rest length l0 - h psi0 must be > 0."""
        return self.height_mm * self.psi0_rad

    def check_l0(self, l0_mm: float, where: str = "l0_mm") -> float:
        """``l0_mm`` if the section fits on it, else a :class:`UserInputError` with the fix.

        Examples
        --------
        >>> from pipeline.model import load_materials
        >>> load_materials()["SS40"].check_l0(30.0)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        pipeline.errors.UserInputError: l0_mm = 30 mm is shorter ... l0 must exceed 51.3 mm; ...
        """
        if not l0_mm > self.min_l0_mm:
            raise UserInputError(
                f"{where} = {l0_mm:g} mm is shorter than {self.name}'s own wall allows: at "
                f"psi0 = {self.psi0_deg:g} deg the top of the section (b + a0 + t0 = "
                f"{self.height_mm:g} mm above the inextensible layer) would have a rest length "
                f"l0 - {self.height_mm:g} mm x psi0 <= 0, so l0 must exceed "
                f"{self.min_l0_mm:.1f} mm; pass the length of the marked layer in mm (the "
                "paper's actuators: 170-270 mm)"
            )
        return float(l0_mm)

    @property
    def area0_mm2(self) -> float:
        """Undeformed area A0 of the semi-circular wall, pi/2 ((a0 + t0)^2 - a0^2), in mm^2."""
        return 0.5 * math.pi * ((self.a0_mm + self.t0_mm) ** 2 - self.a0_mm**2)

    def ogden_terms(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """Ogden terms with *identical* exponents summed (exact: mu1 x^a + mu2 x^a = (mu1+mu2) x^a).

        Terms with different exponents (DS20, whose moduli nearly cancel) are kept separate.

        Returns
        -------
        mu_mpa, alpha : tuple of float
        """
        merged: dict[float, float] = {}
        for mu, alpha in zip(self.mu_mpa, self.alpha, strict=True):
            merged[alpha] = merged.get(alpha, 0.0) + mu
        return tuple(merged.values()), tuple(merged.keys())


def _number(value: Any, where: str, key: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise UserInputError(f"{where}: key '{key}' must be a number, got {value!r}") from None
    if not math.isfinite(out):
        raise UserInputError(f"{where}: key '{key}' must be finite, got {value!r}")
    return out


def _parse_material(name: str, raw: Any, geometry: dict[str, Any], where: str) -> Material:
    here = f"{where}: materials.{name}"
    if not isinstance(raw, dict):
        raise UserInputError(
            f"{here} must be a mapping with keys mu_mpa, alpha, k_p (and optional k_t)"
        )
    for key in ("mu_mpa", "alpha", "k_p"):
        if key not in raw:
            raise UserInputError(
                f"{here}: missing key '{key}'; add it (see pipeline/model/materials.yaml)"
            )
    mu = raw["mu_mpa"] if isinstance(raw["mu_mpa"], list) else [raw["mu_mpa"]]
    alpha = raw["alpha"] if isinstance(raw["alpha"], list) else [raw["alpha"]]
    if len(alpha) == 1 and len(mu) > 1:  # one shared exponent, as Table I writes it for DS30
        alpha = alpha * len(mu)
    if len(mu) != len(alpha) or not mu:
        raise UserInputError(
            f"{here}: 'mu_mpa' and 'alpha' must be lists of the same non-zero length"
        )
    mu_t = tuple(_number(m, here, "mu_mpa") for m in mu)
    alpha_t = tuple(_number(a, here, "alpha") for a in alpha)
    if any(a == 0.0 for a in alpha_t):
        raise UserInputError(f"{here}: Ogden exponents 'alpha' must be non-zero")
    k_t_raw = raw.get("k_t")
    k_t = None if k_t_raw is None else _number(k_t_raw, here, "k_t")
    geo = {k: raw.get(k, geometry.get(k)) for k in _GEOMETRY_KEYS}
    for key, value in geo.items():
        if value is None:
            raise UserInputError(f"{here}: geometry key '{key}' missing here and under 'geometry:'")
    geo_f = {k: _number(v, here, k) for k, v in geo.items()}
    for key in ("b_mm", "a0_mm", "t0_mm", "l0_mm", "psi0_deg"):
        if geo_f[key] <= 0:
            raise UserInputError(f"{here}: '{key}' must be > 0, got {geo_f[key]}")
    k_p = _number(raw["k_p"], here, "k_p")
    if k_p <= 0:
        raise UserInputError(f"{here}: 'k_p' must be > 0, got {k_p}")
    mat = Material(
        name=str(name),
        mu_mpa=mu_t,
        alpha=alpha_t,
        k_p=k_p,
        k_t=k_t,
        description=str(raw.get("description", "")),
        **geo_f,
    )
    mat.check_l0(mat.l0_mm, where=f"{here}: l0_mm")
    return mat


@functools.lru_cache(maxsize=16)
def _load_cached(path: str, mtime_ns: int) -> dict[str, Material]:
    where = path
    try:
        data = yaml.safe_load(read_user_text(path))
    except OSError as exc:
        raise UserInputError(
            f"{where}: cannot read materials file ({exc.strerror}); check the path"
        ) from None
    except yaml.YAMLError as exc:
        raise UserInputError(f"{where}: not valid YAML ({exc}); fix the syntax") from None
    if not isinstance(data, dict) or not isinstance(data.get("materials"), dict):
        raise UserInputError(
            f"{where}: needs a top-level 'materials:' mapping (see pipeline/model/materials.yaml)"
        )
    geometry = data.get("geometry") or {}
    if not isinstance(geometry, dict):
        raise UserInputError(
            f"{where}: 'geometry:' must be a mapping of {', '.join(_GEOMETRY_KEYS)}"
        )
    return {
        str(n): _parse_material(str(n), raw, geometry, where)
        for n, raw in data["materials"].items()
    }


def load_materials(path: str | os.PathLike[str] | None = None) -> dict[str, Material]:
    """Load the materials data file.

    Parameters
    ----------
    path : path-like, optional
        YAML file with ``geometry:`` defaults and a ``materials:`` mapping; the packaged
        ``materials.yaml`` (DS20, DS30, SS40, SS50) when omitted.

    Returns
    -------
    dict of str to Material

    Raises
    ------
    pipeline.errors.UserInputError
        If the file is missing, malformed, or a material lacks a key.

    Examples
    --------
    >>> from pipeline.model import load_materials
    >>> load_materials()["DS20"].psi0_deg
    210.0
    """
    p = Path(DEFAULT_MATERIALS_PATH if path is None else path).resolve()
    try:
        mtime = p.stat().st_mtime_ns
    except OSError:
        raise UserInputError(f"{p}: materials file not found; pass an existing YAML path") from None
    return dict(_load_cached(str(p), mtime))


def resolve_material(material: str | Material) -> Material:
    """Return ``material`` itself, or the packaged material of that name.

    Raises
    ------
    pipeline.errors.UserInputError
        For an unknown name.
    """
    if isinstance(material, Material):
        return material
    table = load_materials()
    if material not in table:
        raise UserInputError(
            f"{DEFAULT_MATERIALS_PATH}: unknown material {material!r}; use one of {sorted(table)} "
            "or load your own file with load_materials(PATH)"
        )
    return table[material]
