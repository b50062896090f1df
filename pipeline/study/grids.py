"""The scenes of the study: sweeps of one condition at a time, the others nominal.

A :class:`Grid` is a list of :class:`Sweep` (one per condition) plus a repeatability block;
:func:`cases` expands it into the :class:`Case` list that :mod:`pipeline.study.run` renders and
measures.  Two grids are defined in :data:`GRIDS`:

``default``
    Small (about 170 images): feeds the default report and must add < 60 s on 2 cores.
``full``
    Fine sweeps (about 1000 images, minutes): ``snakemake bench``.

The nominal scene is the synthetic renderer's ``lab`` preset (1280 x 960 px, 0.3 mm/px, noise
2.5 grey levels, blur 0.8 px, JPEG 90, 5 grey distractor marks, tilt 1 deg) with a 195 mm line
(650 px long).  For every sweep but ``psi`` each sweep value is rendered at several angles
(``psis_deg``) so that a 95th percentile means something.

Examples
--------
>>> g = GRIDS["default"]
>>> [s.name for s in g.sweeps][:3]
['psi', 'noise', 'blur']
>>> c = cases(g)
>>> len(c) == len({x.case_id for x in c})
True
"""

from __future__ import annotations

from dataclasses import dataclass

from pipeline.errors import UserInputError

#: nominal scene preset of :mod:`pipeline.synth`
NOMINAL_PRESET = "lab"
#: length of the marked line (mm) in every scene
L0_MM = 195.0
#: nominal image width (px) and scale (mm/px) of the preset: line length 650 px
NOMINAL_WIDTH_PX = 1280
NOMINAL_MM_PER_PX = 0.3


@dataclass(frozen=True)
class Sweep:
    """One condition swept, every other knob nominal.

    Attributes
    ----------
    name : str
        Condition name used in the tables (``psi``, ``noise``, ...).
    label : str
        Axis label with unit.
    knob : str
        What the value sets: ``psi_deg``, ``bulge``, ``line_length_px`` (via the image width,
        same field of view), or a field of ``pipeline.synth.SceneParams``.
    values : tuple of float
        Sweep values (ascending).
    nominal : float
        Value of the nominal scene; breakdown points are searched outward from it.
    psis_deg : tuple of float
        Bending angles rendered at each value (ignored when ``knob == "psi_deg"``).
    seeds : int
        Noise seeds per (value, angle).
    fixed : tuple of (str, object)
        Extra scene overrides held for the whole sweep (e.g. ink-coloured distractors).
    """

    name: str
    label: str
    knob: str
    values: tuple[float, ...]
    nominal: float
    psis_deg: tuple[float, ...] = ()
    seeds: int = 1
    fixed: tuple[tuple[str, object], ...] = ()


@dataclass(frozen=True)
class Grid:
    """A study: sweeps plus a repeatability block (one scene, ``repeat_seeds`` noise seeds)."""

    name: str
    sweeps: tuple[Sweep, ...]
    repeat_psis_deg: tuple[float, ...]
    repeat_seeds: int = 20
    preset: str = NOMINAL_PRESET
    l0_mm: float = L0_MM


@dataclass(frozen=True)
class Case:
    """One synthetic image: what to render and the truth to score against.

    Attributes
    ----------
    case_id : int
        Index in the grid (also used to derive the seed of sweep images).
    kind : str
        ``sweep`` or ``repeat``.
    condition : str
        Sweep name (``repeat`` for the repeatability block).
    value : float
        Sweep value (for ``repeat``: the angle).
    nominal : float
        Nominal value of the sweep.
    psi_deg : float
        True total turning angle (deg).
    bulge : float
        Non-constant curvature amount of ``pipeline.synth.centreline_mm`` (0 = circular arc).
    seed : int
        Renderer seed (noise, marks, lighting direction).
    overrides : tuple of (str, object)
        ``pipeline.synth.scene_from`` overrides of the preset.
    preset : str
    l0_mm : float
    """

    case_id: int
    kind: str
    condition: str
    value: float
    nominal: float
    psi_deg: float
    bulge: float
    seed: int
    overrides: tuple[tuple[str, object], ...]
    preset: str
    l0_mm: float


def scene_overrides(knob: str, value: float) -> tuple[tuple[str, object], ...]:
    """Scene overrides that set ``knob`` to ``value`` (empty for ``psi_deg`` and ``bulge``).

    ``line_length_px`` changes the image size with the same field of view, so the line is
    ``value`` pixels long (``scene_from`` rescales ``mm_per_px``, line width and blur).

    Examples
    --------
    >>> scene_overrides("line_length_px", 325.0)
    (('width', 640), ('height', 480))
    >>> scene_overrides("jpeg_quality", 50.0)
    (('jpeg_quality', 50),)
    """
    if knob in ("psi_deg", "bulge"):
        return ()
    if knob == "line_length_px":
        nominal_px = L0_MM / NOMINAL_MM_PER_PX
        width = round(NOMINAL_WIDTH_PX * value / nominal_px / 4.0) * 4
        return (("width", width), ("height", width * 3 // 4))
    if knob in ("jpeg_quality", "distractor_marks"):
        return ((knob, round(value)),)
    return ((knob, float(value)),)


def cases(grid: Grid, *, base_seed: int = 1) -> list[Case]:
    """Expand a grid into the list of images to render, deterministically.

    Parameters
    ----------
    grid : Grid
    base_seed : int
        Seeds of sweep images are ``base_seed * 100003 + case_id``; repeatability images use
        seeds ``base_seed * 100003 + 90000 + k``, ``k = 0 .. repeat_seeds - 1``.

    Returns
    -------
    list of Case
    """
    out: list[Case] = []

    def add(kind: str, sweep_name: str, value: float, nominal: float, psi: float, bulge: float,
            seed: int | None, overrides: tuple[tuple[str, object], ...]) -> None:
        cid = len(out)
        out.append(
            Case(
                cid,
                kind,
                sweep_name,
                float(value),
                float(nominal),
                float(psi),
                float(bulge),
                base_seed * 100003 + cid if seed is None else seed,
                overrides,
                grid.preset,
                grid.l0_mm,
            )
        )

    for sweep in grid.sweeps:
        for value in sweep.values:
            psis = (value,) if sweep.knob == "psi_deg" else sweep.psis_deg
            bulge = value if sweep.knob == "bulge" else 0.0
            ov = sweep.fixed + scene_overrides(sweep.knob, value)
            for psi in psis:
                for _ in range(sweep.seeds):
                    add("sweep", sweep.name, value, sweep.nominal, psi, bulge, None, ov)
    for psi in grid.repeat_psis_deg:
        for k in range(grid.repeat_seeds):
            add("repeat", "repeat", psi, psi, psi, 0.0, base_seed * 100003 + 90000 + k, ())
    return out


def get_grid(name: str) -> Grid:
    """The grid called ``name`` (a key of :data:`GRIDS`).

    Raises
    ------
    UserInputError
        When there is no such grid.
    """
    if name not in GRIDS:
        raise UserInputError(f"--grid {name!r} is unknown; use one of {sorted(GRIDS)}")
    return GRIDS[name]


# ---------------------------------------------------------------------------------------------
# the two grids

_PSI_DEFAULT = (
    -360,
    -330,
    -270,
    -190,
    -180,
    -170,
    -90,
    -30,
    -3,
    -1,
    0,
    1,
    3,
    30,
    90,
    170,
    180,
    190,
    210,
    270,
    330,
    360,
)
_PSI_FULL = tuple(sorted(
    set(range(-360, 361, 30))
    | {-3, -2, -1, -0.5, -0.25, 0, 0.25, 0.5, 1, 2, 3, 5, 10}  # radius unbounded at 0
    | {s * v for s in (-1, 1) for v in (170, 175, 178, 180, 182, 185, 190, 200)}  # ends across
    | {s * v for s in (-1, 1) for v in (310, 320, 340, 350)}  # ends approaching / touching
))


def _sweeps(fine: bool) -> tuple[Sweep, ...]:
    psis = (-200.0, -90.0, -20.0, 30.0, 120.0, 210.0, 300.0) if fine else (-150.0, 60.0, 210.0)

    def sw(name: str, label: str, knob: str, coarse: tuple[float, ...], full: tuple[float, ...],
           nominal: float, **kw: object) -> Sweep:
        values = tuple(float(v) for v in (full if fine else coarse))
        return Sweep(name, label, knob, values, float(nominal), psis, **kw)  # type: ignore[arg-type]

    sweeps = [
        Sweep(
            "psi",
            "true bending angle psi (deg)",
            "psi_deg",
            tuple(float(v) for v in (_PSI_FULL if fine else _PSI_DEFAULT)),
            0.0,
            (),
            3 if fine else 2,
        ),
        sw(
            "noise",
            "sensor noise sigma (grey levels)",
            "noise_sigma",
            (0, 2.5, 8, 20),
            (0, 1, 2.5, 5, 8, 12, 20, 30, 45),
            2.5,
        ),
        sw(
            "blur",
            "optical blur sigma (px)",
            "blur_sigma_px",
            (0, 0.8, 2, 4),
            (0, 0.4, 0.8, 1.5, 2, 3, 4, 6, 8),
            0.8,
        ),
        sw(
            "jpeg",
            "JPEG quality (1-100)",
            "jpeg_quality",
            (20, 50, 90, 95),
            (5, 10, 20, 35, 50, 60, 75, 90, 95, 100),
            90,
        ),
        sw(
            "contrast",
            "line contrast (ink opacity, 0-1)",
            "line_contrast",
            (0.25, 0.5, 0.95, 1.0),
            (0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 0.95, 1.0),
            0.95,
        ),
        sw(
            "resolution",
            "line length (px)",
            "line_length_px",
            (120, 300, 650),
            (50, 80, 120, 200, 300, 450, 650, 975, 1300),
            650,
        ),
        sw(
            "width",
            "line width (px)",
            "line_width_px",
            (1.5, 6, 14),
            (1, 1.5, 2, 3, 4, 6, 9, 14, 20),
            6,
        ),
        sw(
            "occlusion",
            "occluded fraction of the line (0-0.5)",
            "occluded_fraction",
            (0, 0.05, 0.15, 0.3),
            (0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5),
            0,
        ),
        sw(
            "clutter",
            "grey distractor marks (count)",
            "distractor_marks",
            (0, 5, 20),
            (0, 5, 10, 20, 40),
            5,
        ),
        sw(
            "tilt",
            "camera tilt (deg)",
            "tilt_deg",
            (0, 1, 5, 12),
            (0, 1, 2, 3, 5, 8, 12, 16, 20),
            1,
        ),
        sw(
            "bulge",
            "non-constant curvature (bulge, 0 = arc)",
            "bulge",
            (0, 0.2, 0.5),
            (0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9),
            0,
        ),
    ]
    if fine:
        sweeps.insert(
            -2,
            sw(
                "clutter_ink",
                "distractor marks in the line's own ink (count)",
                "distractor_marks",
                (),
                (0, 1, 2, 5, 10, 20),
                0,
                fixed=(("distractor_color", "line"),),
            ),
        )
    return tuple(sweeps)


#: the named grids
GRIDS: dict[str, Grid] = {
    "default": Grid("default", _sweeps(False), repeat_psis_deg=(120.0,)),
    "full": Grid("full", _sweeps(True), repeat_psis_deg=(0.0, 120.0, -200.0, 300.0)),
}
