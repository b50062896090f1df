"""Everything the report shows, loaded and checked once: a :class:`ReportData`.

The pages are pure functions of this object, so the PDF depends on the inputs' content only
(never on the clock, the machine or file times): the date printed on page 1 is the date the
photos were taken, read from the inputs (:func:`dataset_dates`).
"""

from __future__ import annotations

import csv
import hashlib
import io
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from pipeline.aggregate import (
    aggregate_hysteresis,
    aggregate_per_actuator,
    pool_hysteresis,
    read_angles,
)
from pipeline.compare import check_hysteresis
from pipeline.errors import UserInputError
from pipeline.fileio import read_table
from pipeline.folders import folder_sha256
from pipeline.force.grasp import EXAMPLE_LOG as GRASP_EXAMPLE
from pipeline.force.pages import FILES as FORCE_FILES
from pipeline.measure.quality import NOTE_RAMP_BACKGROUND
from pipeline.measure.settings import OVERRIDE_COLUMNS
from pipeline.photo_times import exif_time
from pipeline.photoset import (
    MANIFEST,
    SETTINGS,
    TRUTH,
    PhotoSet,
    load_photoset,
    measurement_doubts,
)
from pipeline.report.accuracy import NO_ACCURACY, AngleAccuracy, angle_accuracy
from pipeline.study.pages import TABLES as BENCH_TABLES


@dataclass(frozen=True)
class Dataset:
    """One measured photo set.

    Attributes
    ----------
    name : str
        Label shown in the report.
    angles_csv : Path
        Its angles.csv (from ``measure``).
    photoset_dir : Path or None
        The photo-set folder (raw photos), if available.
    overlays_dir : Path or None
        The ``measure --overlays`` folder (``<image stem>.jpg`` with the extracted line), if any.
    """

    name: str
    angles_csv: Path
    photoset_dir: Path | None = None
    overlays_dir: Path | None = None


@dataclass(frozen=True)
class ReportInputs:
    """Files the report is built from (see ``python -m pipeline report --help``)."""

    datasets: tuple[Dataset, ...]
    hysteresis: tuple[Path, ...] = ()
    rms: tuple[Path, ...] = ()
    model_curves: tuple[Path, ...] = ()
    bench_dir: Path | None = None
    force_dir: Path | None = None
    video_dirs: tuple[Path, ...] = ()
    materials_files: tuple[Path, ...] = ()
    config: Path | None = None
    title: str = "Circular actuator characterisation"


@dataclass(frozen=True)
class InputFile:
    """One file the report was built from, for the provenance page."""

    role: str
    path: str
    sha256: str


@dataclass(frozen=True)
class DatasetInfo:
    """What the report says about a dataset besides its numbers.

    Attributes
    ----------
    name : str
    source : str
        ``"synthetic"`` (its photo set holds the renderer's ``truth.csv``), ``"real"`` (a photo
        set without one) or ``"unknown"`` (no photo-set folder given).
    first_date, last_date : str or None
        ``YYYY-MM-DD`` of the first and last photo, from the manifest's ``timestamp`` column
        or else the photos' EXIF dates; ``None`` when the inputs hold no date.
    date_source : str
        Where the dates come from (``"timestamps"``, ``"EXIF"`` or ``""``); without dates, why
        the timestamps could not be read as dates, or ``""``.
    settings : str
        How its photos were measured, in words (:func:`settings_words`); ``""`` without a
        readable photo set.
    doubts : tuple of str
        What its photo set leaves doubtful or unmeasured whatever its rows say
        (:func:`photoset_doubts`).
    accuracy : AngleAccuracy
        How well its angles were measured (:func:`pipeline.report.accuracy.angle_accuracy`).
    """

    name: str
    source: str
    first_date: str | None
    last_date: str | None
    date_source: str
    settings: str = ""
    doubts: tuple[str, ...] = ()
    accuracy: AngleAccuracy = NO_ACCURACY


@dataclass(frozen=True)
class ReportData:
    """Loaded tables.

    Attributes
    ----------
    inputs : ReportInputs
    angles : pandas.DataFrame
        All angles rows with a ``dataset`` column holding the dataset *name*.
    hysteresis : pandas.DataFrame
        Pooled hysteresis per material x direction x level.
    per_actuator : pandas.DataFrame
        Per-actuator curves (from the angles, default exclusions).
    rms : pandas.DataFrame
        rms.csv rows (may be empty).
    model_curves : pandas.DataFrame
        ``material``, ``psi_deg``, ``pressure_kpa`` (may be empty).
    files : tuple of InputFile
        Every input file with its sha256, in a fixed order; angles tables without their timing
        column (:func:`sha256_measurements`).
    datasets : tuple of DatasetInfo
        Source and dates of each dataset, in input order.
    notes : list of str
        Things the reader should know (e.g. hysteresis recomputed from angles).
    run_config : dict
        The run's resolved config (``--config``), read once (:func:`read_run_config`); empty
        without one.
    """

    inputs: ReportInputs
    angles: pd.DataFrame
    hysteresis: pd.DataFrame
    per_actuator: pd.DataFrame
    rms: pd.DataFrame
    model_curves: pd.DataFrame
    files: tuple[InputFile, ...]
    datasets: tuple[DatasetInfo, ...]
    notes: list[str] = field(default_factory=list)
    run_config: dict[str, Any] = field(default_factory=dict)

    @property
    def materials(self) -> list[str]:
        """Materials in the data, sorted by name."""
        return sorted(self.hysteresis["material"].astype(str).unique())


def sha256_file(path: str | os.PathLike[str]) -> str:
    """Hex sha256 of a file's bytes.

    Raises
    ------
    UserInputError
        If the file cannot be read.
    """
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    except OSError as exc:
        raise UserInputError(f"{path}: cannot read ({exc.strerror}); check the path") from None
    return h.hexdigest()


TIMING_COLUMNS: tuple[str, ...] = ("seconds",)


def sha256_measurements(
    path: str | os.PathLike[str], timing: Sequence[str] = TIMING_COLUMNS
) -> str:
    """Hex sha256 of a CSV table without its run-time columns (``seconds``).

    A measure job records how long each photo took; two runs on the same photos (on a
    workstation or on a cluster) differ only there. The rest of the table, re-written with
    ``\\n`` line ends, identifies the measurements. A table without such a column gets the
    digest of its bytes, as :func:`sha256_file`.

    Raises
    ------
    UserInputError
        If the file cannot be read.
    """
    try:
        with open(path, encoding="utf-8", newline="") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise UserInputError(f"{path}: cannot read ({exc}); check the path") from None
    rows = list(csv.reader(io.StringIO(text)))
    drop = {i for i, name in enumerate(rows[0] if rows else []) if name in timing}
    if not drop:
        return sha256_file(path)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerows([v for i, v in enumerate(row) if i not in drop] for row in rows)
    return hashlib.sha256(out.getvalue().encode("utf-8")).hexdigest()


def _read_csv(path: Path, what: str, required: Sequence[str]) -> pd.DataFrame:
    return read_table(path, f"a {what}", required=required)


def load_report_data(inputs: ReportInputs) -> ReportData:
    """Read and check every input of the report.

    Parameters
    ----------
    inputs : ReportInputs

    Returns
    -------
    ReportData

    Raises
    ------
    UserInputError
        Missing/unreadable files, missing columns, duplicate dataset names.
    """
    if not inputs.datasets:
        raise UserInputError("no dataset given; pass at least one --angles ANGLES.csv")
    names = [d.name for d in inputs.datasets]
    if len(set(names)) != len(names):
        raise UserInputError(f"--datasets: names must be unique, got {names}")
    frames = []
    for d in inputs.datasets:
        a = read_angles([d.angles_csv])
        a["dataset"] = d.name
        frames.append(a)
    angles = pd.concat(frames, ignore_index=True)
    notes: list[str] = []
    if inputs.hysteresis:
        parts = []
        for p in inputs.hysteresis:
            h = _read_csv(p, "hysteresis.csv written by 'aggregate'", ())
            check_hysteresis(h, str(p))
            parts.append(h)
        hysteresis = pool_hysteresis(pd.concat(parts, ignore_index=True))
    else:
        hysteresis = aggregate_hysteresis(angles)
        notes.append(
            "hysteresis recomputed from the angles (setpoint levels, ok rows only): no "
            "--hysteresis given"
        )
    run_config = read_run_config(inputs.config)
    infos = tuple(dataset_info(d, angles[angles["dataset"] == d.name]) for d in inputs.datasets)
    plotted = angles
    pooled = mixed_materials(angles, infos)
    if pooled:  # real beside synthetic photos of one material: its plots show the real ones
        options = aggregate_options(run_config)
        left_out = [
            str(d) in pooled.get(str(m), ((), ()))[1]
            for m, d in zip(angles["material"], angles["dataset"], strict=True)
        ]
        plotted = angles[~pd.Series(left_out, index=angles.index)]
        again = plotted[plotted["material"].astype(str).isin(pooled)]
        hysteresis = pd.concat(
            [
                hysteresis[~hysteresis["material"].astype(str).isin(pooled)],
                aggregate_hysteresis(again, **options),
            ],
            ignore_index=True,
        )
    per_actuator = aggregate_per_actuator(plotted)
    rms = (
        pd.concat(
            [_read_csv(p, "rms.csv written by 'compare'", ("material",)) for p in inputs.rms],
            ignore_index=True,
        )
        if inputs.rms
        else pd.DataFrame(columns=["material"])
    )
    key = "curve" if "curve" in rms.columns else "material"  # one row per material and l0
    if rms[key].duplicated().any():
        dup = rms.loc[rms[key].duplicated(), key].iloc[0]
        raise UserInputError(f"--rms: {key} {dup!r} appears twice; pass one rms.csv row per {key}")
    curves = (
        pd.concat(
            [
                _read_csv(
                    p, "model curve CSV from 'model curve'", ("material", "psi_deg", "pressure_kpa")
                )
                for p in inputs.model_curves
            ],
            ignore_index=True,
        )
        if inputs.model_curves
        else pd.DataFrame(columns=["material", "psi_deg", "pressure_kpa"])
    )
    if not inputs.model_curves:
        notes.append("no --model-curves given: plots show the measurements only")
    if inputs.config is not None:
        notes.append(model_readings_note(run_config))
    return ReportData(
        inputs=inputs,
        angles=angles,
        hysteresis=hysteresis,
        per_actuator=per_actuator,
        rms=rms,
        model_curves=curves,
        files=input_files(inputs),
        notes=notes,
        datasets=infos,
        run_config=run_config,
    )


def input_files(inputs: ReportInputs) -> tuple[InputFile, ...]:
    """Every file the report reads, with its sha256 (angles tables without their run-time column,
    :func:`sha256_measurements`), and each photo set's folder, photos and all, with one sha256
    over every file in it (:func:`pipeline.folders.folder_sha256`)."""
    files: list[tuple[str, Path]] = []
    folders: list[InputFile] = []
    for d in inputs.datasets:
        files.append((f"{d.name}: angles", d.angles_csv))
        if d.photoset_dir is not None:
            files += [
                (f"{d.name}: photo set", d.photoset_dir / n)
                for n in (MANIFEST, SETTINGS)
                if (d.photoset_dir / n).is_file()
            ]
            if d.photoset_dir.is_dir():
                digest, n = folder_sha256(d.photoset_dir)
                folders.append(
                    InputFile(f"{d.name}: every file of the photo set ({n})", str(d.photoset_dir),
                              digest)
                )
    files += [("hysteresis", p) for p in inputs.hysteresis]
    files += [("comparison", p) for p in inputs.rms]
    files += [("model curve", p) for p in inputs.model_curves]
    files += [("materials file", p) for p in inputs.materials_files]
    for role, folder, names in (
        ("bench", inputs.bench_dir, BENCH_TABLES),
        ("force", inputs.force_dir, FORCE_FILES),
    ):
        if folder is not None:
            files += [(role, folder / n) for n in names if (folder / n).is_file()]
    if inputs.config is not None:
        files.append(("config", inputs.config))
    return tuple(
        InputFile(
            role, str(p), sha256_measurements(p) if role.endswith(": angles") else sha256_file(p)
        )
        for role, p in files
    ) + tuple(folders)


def mixed_materials(
    angles: pd.DataFrame, infos: Sequence[DatasetInfo]
) -> dict[str, tuple[tuple[str, ...], tuple[str, ...]]]:
    """The materials with both real and synthetic photo sets: material -> (real, synthetic)
    dataset names.

    Examples
    --------
    >>> a = pd.DataFrame({"material": ["DS20", "DS20", "SS40"],
    ...                   "dataset": ["mine", "DS20", "SS40"]})
    >>> infos = [DatasetInfo("mine", "real", None, None, ""),
    ...          DatasetInfo("DS20", "synthetic", None, None, ""),
    ...          DatasetInfo("SS40", "synthetic", None, None, "")]
    >>> mixed_materials(a, infos)
    {'DS20': (('mine',), ('DS20',))}
    """
    kind = {d.name: d.source for d in infos}
    out = {}
    for material, names in angles.groupby(angles["material"].astype(str))["dataset"]:
        names = sorted(names.astype(str).unique())
        real = tuple(n for n in names if kind.get(n) == "real")
        synthetic = tuple(n for n in names if kind.get(n) == "synthetic")
        if real and synthetic:
            out[str(material)] = (real, synthetic)
    return out


def material_sources(data: ReportData) -> dict[str, str]:
    """Per material: ``synthetic``, ``real``, ``real + synthetic`` or ``unknown``."""
    by_dataset = {d.name: d.source for d in data.datasets}
    out = {}
    for m in data.materials:
        names = sorted(
            data.angles.loc[data.angles["material"].astype(str) == m, "dataset"]
            .astype(str)
            .unique()
        )
        kinds = sorted({by_dataset[n] for n in names if n in by_dataset})
        out[m] = " + ".join(kinds) if kinds else "unknown"
    return out


def mixed_sources_note(data: ReportData, material: str) -> str:
    """A sentence when ``material`` has real and synthetic photo sets: its plots show the real
    ones (the tables, from ``compare``, keep each on its own row), else ``""``."""
    pooled = mixed_materials(data.angles, data.datasets).get(material)
    if pooled is None:
        return ""
    real, synthetic = pooled
    return (
        f"{material}: the plots and the photo strip show the real photos ({', '.join(real)}) "
        f"only; the synthetic ones ({', '.join(synthetic)}) are left out of them.  The tables "
        "compare each with the model on its own."
    )


def read_run_config(config_path: Path | None) -> dict[str, Any]:
    """The run's resolved config (``--config``) as a mapping, read once; empty without one.

    Raises
    ------
    UserInputError
        If the file cannot be read as YAML.
    """
    import yaml

    if config_path is None:
        return {}
    try:
        cfg = yaml.safe_load(Path(config_path).read_text(encoding="utf-8")) or {}
    except (OSError, yaml.YAMLError) as exc:
        raise UserInputError(
            f"--config {config_path}: cannot read it as YAML ({exc}); pass the resolved config"
        ) from None
    return cfg if isinstance(cfg, dict) else {}


def force_inputs(run_config: dict[str, Any]) -> tuple[tuple[str, ...], bool]:
    """From the run's (resolved) config: the materials of its synthetic blocked-force sets, and
    whether its grasp log is the paper's example (the shipped file's bytes), so that the force
    pages can say what was not measured; nothing without a config."""
    force = run_config.get("force") or {}
    synthetic = sorted(
        {
            str(d["material"])
            for d in force.get("datasets") or []
            if isinstance(d, dict) and d.get("source") == "synthetic" and d.get("material")
        }
    )
    log = force.get("grasp_log")
    example = (
        isinstance(log, str)
        and Path(log).is_file()
        and Path(log).read_bytes() == GRASP_EXAMPLE.read_bytes()
    )
    return tuple(synthetic), example


def aggregate_options(run_config: dict[str, Any]) -> dict[str, Any]:
    """``bin_kpa`` and ``include_flagged`` of the run's ``aggregate`` settings (the resolved
    config), as ``aggregate`` used them; the defaults without a config."""
    agg = run_config.get("aggregate") or {}
    return {
        "bin_kpa": agg.get("bin_kpa"),
        "include_flagged": bool(agg.get("include_flagged", False)),
    }


def dataset_info(dataset: Dataset, angles: pd.DataFrame) -> DatasetInfo:
    """Source (synthetic, real or unknown) and photo dates of one dataset."""
    folder = dataset.photoset_dir
    source = (
        "unknown"
        if folder is None or not folder.is_dir()
        else ("synthetic" if (folder / TRUTH).is_file() else "real")
    )
    first, last, where = dataset_dates(angles, folder)
    ps = None
    if folder is not None and (folder / SETTINGS).is_file():
        try:
            ps = load_photoset(folder)
        except UserInputError:
            ps = None  # its rows were measured when it could be read
    return DatasetInfo(
        dataset.name,
        source,
        first,
        last,
        where,
        settings="" if ps is None else settings_words(ps.settings, ps.manifest, angles),
        doubts=() if ps is None else photoset_doubts(dataset.name, ps),
        accuracy=angle_accuracy(angles, _truth(folder) if source == "synthetic" else None),
    )


def _truth(folder: Path | None) -> pd.DataFrame | None:
    """The renderer's truth.csv of a photo set, or None when it cannot be read."""
    assert folder is not None  # a synthetic set's folder
    try:
        return read_table(folder / TRUTH, "the renderer's truth.csv")
    except UserInputError:
        return None


#: a body's settings that, not given, leave something to the measurement, and what it does
NOT_GIVEN_WORDS: dict[str, str] = {
    "mm_per_px": "no scale",
    "fixed_direction_deg": "the base direction read from the photos, each ramp's median",
    "background": "no empty scene",
    "sealed_end_mm": "the tip read where the centre line stops",
}


def settings_words(
    settings: Mapping[str, Any], manifest: pd.DataFrame, angles: pd.DataFrame | None = None
) -> str:
    r"""How a photo set was measured, in one line: its settings that have a value, the manifest's
    per-row setting columns (how many rows give one), for a body the settings not given (and
    what was done without them), and from its ``angles`` the method each row took and how many
    rows were measured again against their ramp's own photos (the second look).

    Examples
    --------
    >>> m = pd.DataFrame({"image": ["a.jpg", "b.jpg"], "exclude": [None, "[[1, 2, 3, 4]]"]})
    >>> settings_words({"l0_mm": 30, "mm_per_px": None, "target": "line"}, m)
    'l0_mm 30, target line; per row: exclude (1 row)'
    >>> a = pd.DataFrame({"method": ["tangents"] * 2, "reason": ["", "measured against the "
    ...                   "empty scene estimated from its ramp's photos (the first look ...)"]})
    >>> words = settings_words({"l0_mm": 30, "target": "body", "sealed_end_mm": 4}, m, a)
    >>> print(*words.replace(", ", ",\n  ").split("; "), sep="\n")
    l0_mm 30,
      target body,
      sealed_end_mm 4
    per row: exclude (1 row)
    not given: mm_per_px (no scale),
      fixed_direction_deg (the base direction read from the photos,
      each ramp's median),
      background (no empty scene)
    method: tangents (2 rows)
    1 row measured again (the second look) against the empty scene estimated from its ramp's photos
    """
    given = [f"{k} {v}" for k, v in settings.items() if v is not None and v != ""]
    per_row = [
        f"{c} ({n} row{'s' if n != 1 else ''})"
        for c in OVERRIDE_COLUMNS
        if c in manifest.columns and (n := int(manifest[c].notna().sum()))
    ]
    parts = [", ".join(given)] + ([f"per row: {', '.join(per_row)}"] if per_row else [])
    if settings.get("target") == "body":
        missing = [
            f"{k} ({why})"
            for k, why in NOT_GIVEN_WORDS.items()
            if settings.get(k) in (None, "")
            and not (k in manifest.columns and manifest[k].notna().any())
        ]
        parts += [f"not given: {', '.join(missing)}"] if missing else []
    if angles is not None and len(angles):
        counts = angles["method"].dropna().astype(str).value_counts()
        if len(counts):
            parts.append(
                "method: "
                + ", ".join(f"{m} ({n} row{'s' if n != 1 else ''})" for m, n in counts.items())
            )
        again = int(
            angles["reason"].fillna("").astype(str).str.contains(NOTE_RAMP_BACKGROUND,
                                                                 regex=False).sum()
        )
        if again:
            parts.append(
                f"{again} row{'s' if again != 1 else ''} measured again (the second look)"
                + NOTE_RAMP_BACKGROUND.removeprefix("measured")
            )
    return "; ".join(parts)


def photoset_doubts(name: str, ps: PhotoSet) -> tuple[str, ...]:
    """What a dataset's photo set leaves doubtful or unmeasured whatever its rows say, one line
    each (:func:`pipeline.photoset.measurement_doubts`).

    ``measure`` prints them, but a Snakemake run keeps that in the job's log, so the report says
    them too (only what the set's content decides, never file times: same inputs, same report).
    """
    return tuple(f"{name}: {p.message}; {p.fix}" for p in measurement_doubts(ps))


def dataset_dates(
    angles: pd.DataFrame, photoset_dir: Path | None
) -> tuple[str | None, str | None, str]:
    """First and last date (``YYYY-MM-DD``) the photos of a dataset were taken.

    From the ``timestamp`` column when it holds dates (``03.12.2026`` is day first, as written
    with dots; with slashes, ``03/12/2026``, the set's own dates must show which comes first: a
    13th or later in one place), else from the EXIF date of the first and last photo (in table
    order); ``(None, None, "")`` when neither exists (synthetic photos carry no date), or
    ``(None, None, why)`` when slashed dates could be read either way.  Never the clock or file
    times, so the same inputs give the same report.
    """
    unclear = ""
    if "timestamp" in angles.columns:
        text = angles["timestamp"].astype("string")
        # a date written with dots is day first wherever it is written so (03.12.2026: 3 December)
        dotted = text.str.match(r"\s*\d{1,2}\.\d{1,2}\.\d{2,4}(\D|$)", na=False).to_numpy(bool)
        # with slashes it is day first in Europe and month first in the US: the set's own dates
        # say which (a 13th or later in one place), else they are not read as dates
        parts = text.str.extract(r"^\s*(\d{1,2})/(\d{1,2})/\d{2,4}(?:\D|$)").astype(float)
        slashed = parts[0].notna().to_numpy(bool)
        day_first = bool((parts[0] > 12).any())
        month_first = bool((parts[1] > 12).any())
        if slashed.any() and day_first == month_first:
            unclear = (
                "timestamps like "
                + repr(str(text[slashed].iloc[0]).strip())
                + " could be day or month first; write them as 2026-12-03"
            )
            slashed_first = None
        else:
            slashed_first = day_first
        first = dotted | (slashed & (slashed_first is True))
        plain = ~dotted & ~slashed | (slashed & (slashed_first is False))
        stamps = pd.concat(
            [
                pd.to_datetime(text[plain], errors="coerce", utc=True, format="mixed"),
                pd.to_datetime(
                    text[first], errors="coerce", utc=True, format="mixed", dayfirst=True
                ),
            ]
        ).dropna()
        if len(stamps):
            return (
                stamps.min().strftime("%Y-%m-%d"),
                stamps.max().strftime("%Y-%m-%d"),
                "timestamps",
            )
    if photoset_dir is None or angles.empty:
        return None, None, unclear
    dates = [exif_date(photoset_dir / str(angles["image"].iloc[i])) for i in (0, -1)]
    found = sorted(d for d in dates if d)
    if not found:
        return None, None, unclear
    return found[0], found[-1], "EXIF"


def exif_date(path: Path) -> str | None:
    """``YYYY-MM-DD`` from a photo's EXIF time (:func:`pipeline.photo_times.exif_time`);
    ``None`` if absent."""
    when = exif_time(path)
    return None if when is None else when.strftime("%Y-%m-%d")


def model_readings_note(run_config: dict[str, Any]) -> str:
    """One line saying which readings of the paper's model the run used (config
    ``model.readings``)."""
    readings = (run_config.get("model") or {}).get("readings") or {}
    if not readings:
        return (
            "model: the paper's Eqs. 1-13 with the default readings (docs/model.md: derived, no "
            "constant fitted to the paper's numbers; l0 is the one parameter its two model results "
            "fix)"
        )
    given = ", ".join(f"{k}={v}" for k, v in sorted(readings.items()))
    return (
        f"model: the paper's Eqs. 1-13 with readings set in the config: {given} "
        "(others default; docs/model.md)"
    )


def modelled_materials(data: ReportData) -> list[str]:
    """The run's materials compared with the model: a model curve, or an RMS against it (the
    others have no dashed line, RMS or fitted k_P: the model has no such material, or neither
    was given)."""
    have = set(data.model_curves["material"].astype(str))
    if "rms_deg" in data.rms.columns:  # compared with the model (its curve maybe not given)
        have |= set(data.rms.loc[data.rms["rms_deg"].notna(), "material"].astype(str))
    return [m for m in data.materials if m in have]


def rms_row(data: ReportData, material: str) -> dict[str, float]:
    """rms.csv row of a material as a dict (empty when absent).

    With several rows (datasets of different l0) this is the first, the model's default l0
    (``compare`` writes it first); the model provenance page lists them all.
    """
    sel = data.rms[data.rms["material"].astype(str) == material]
    if sel.empty:
        return {}
    return {k: v for k, v in sel.iloc[0].to_dict().items()}


def comparisons(data: ReportData) -> list[tuple[str, str, dict[str, object]]]:
    """``(material, label, rms.csv row)`` of every comparison, materials in order.

    A material has one comparison per l0 (``compare`` writes one row per model curve, the
    model's default l0 first); with one, its label is the material, with several the curve and
    its datasets, e.g. ``"DS20, l0 270 mm (sample)"``.  A material without a row gets ``{}``.
    """
    out: list[tuple[str, str, dict[str, object]]] = []
    for m in data.materials:
        rows = data.rms[data.rms["material"].astype(str) == m].to_dict("records")
        if not rows:
            out.append((m, m, {}))
        for r in rows:
            label = m if len(rows) == 1 else f"{r.get('curve', m)} ({r.get('datasets', '')})"
            out.append((m, label, r))
    return out
