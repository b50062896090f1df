"""The report page of a video dataset: psi and pressure over time, loops, settling, step responses.

:func:`figures` reads the folder written by ``python -m pipeline continuous`` for one dataset
(:data:`pipeline.video.continuous.FILES`; the folder's name is the dataset's) and returns one
A4 page:

- psi and the pressure (setpoint and measured) against time, failed frames marked;
- the hysteresis loops: psi per pressure bin, rising and falling, per cycle;
- the settling curves: the normalised response ``(psi - before) / change`` against the time
  since each step;
- the step-response table (rise time, overshoot, settling time per step) and the loop table
  (leg rates, loop width and area per cycle);
- frames across the recording with the extracted line drawn (``strip.jpg``, when the overlays
  were given to ``continuous``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from pipeline.constants import RAMP_KEYS
from pipeline.layout.style import A4_PORTRAIT_IN, MIN_FONT_PT, footer_fraction, text_page
from pipeline.video.continuous import UNSETTLED

#: step rows shown in the table (the rest are counted)
MAX_TABLE_ROWS = 12
#: frames strip written by ``continuous --overlays``
STRIP = "strip.jpg"
#: frames in the strip
STRIP_FRAMES = 6
#: the strip's captions, one row per tile
STRIP_CAPTIONS = "strip.csv"
STRIP_CAPTION_COLUMNS: tuple[str, ...] = ("frame", "time_s", "pressure_kpa", "psi_deg", "status")


def write_strip(
    angles: pd.DataFrame, overlays_dir: Path, out_dir: Path, n: int = STRIP_FRAMES
) -> Path | None:
    """Write ``strip.jpg``: ``n`` frame overlays evenly spread over the recording (None: no overlay
    found)."""
    import cv2

    from pipeline.fileio import atomic_write_bytes, write_table
    from pipeline.measure.overlay import contact_sheet
    from pipeline.video.measure import frame_overlay_name

    frames = angles[angles["frame"].notna()].sort_values("time_s", kind="stable")
    paths = [
        Path(overlays_dir) / frame_overlay_name(str(i), int(k))
        for i, k in zip(frames["image"], frames["frame"])
    ]
    drawn = [j for j, p in enumerate(paths) if p.is_file()]
    if not drawn:
        return None
    pick = [
        drawn[int(i)]
        for i in np.unique(np.round(np.linspace(0, len(drawn) - 1, min(n, len(drawn)))).astype(int))
    ]
    ok, buf = cv2.imencode(
        ".jpg",
        contact_sheet([paths[j] for j in pick], columns=len(pick), tile_width_px=320),
        [cv2.IMWRITE_JPEG_QUALITY, 85],
    )
    if not ok:
        return None
    atomic_write_bytes(Path(out_dir) / STRIP, buf.tobytes())
    # the tiles' captions, written on the page at a size that can be read (their own bands are
    # too small there: customer 27)
    columns = [c for c in STRIP_CAPTION_COLUMNS if c in frames.columns]
    write_table(frames.iloc[pick][columns], Path(out_dir) / STRIP_CAPTIONS)
    return Path(out_dir) / STRIP


def strip_caption(row: pd.Series) -> str:
    """A strip tile's caption: frame, time, pressure, psi and status.

    Examples
    --------
    >>> strip_caption(pd.Series({"frame": 120, "time_s": 4.5, "pressure_kpa": 40.0,
    ...                          "psi_deg": 183.42, "status": "ok"}))
    'frame 120\\n4.50 s, 40 kPa\\nψ +183.4° ok'
    """
    psi = float(row.get("psi_deg", np.nan))
    return (
        f"frame {int(row['frame'])}\n{_fmt(row.get('time_s'))} s, "
        f"{_fmt(row.get('pressure_kpa'), 0)} kPa\n"
        + (f"ψ {psi:+.1f}° " if np.isfinite(psi) else "ψ n/a ")
        + str(row.get("status", ""))
    )


def _read(folder: Path, name: str) -> pd.DataFrame:
    path = folder / name
    if not path.is_file() or path.stat().st_size == 0:
        return pd.DataFrame()
    try:
        return pd.read_csv(path, dtype={"actuator": str, "trial": str})
    except pd.errors.EmptyDataError:
        return pd.DataFrame()


def _label(row: pd.Series) -> str:
    return f"{row['material']} {row['actuator']} t{row['trial']}"


def _fmt(value: object, digits: int = 2) -> str:
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return str(value)
    return "n/a" if not np.isfinite(v) else f"{v:.{digits}f}"


def cycle_summary(
    cycles: pd.DataFrame, *, stepped: bool, steps: pd.DataFrame | None = None
) -> str:
    r"""The line under the loops: each cycle's rates and loop width, and, for a continuous ramp
    (no steps), that its loop holds the actuator's lag as well as its hysteresis.

    Examples
    --------
    >>> c = pd.DataFrame([{"material": "DS30", "actuator": "A1", "trial": 1, "cycle": 1,
    ...     "rate_up_kpa_s": 8.0, "rate_down_kpa_s": 8.0, "width_mean_deg": 45.7,
    ...     "width_max_deg": 105.8, "width_max_at_kpa": 105.0, "area_deg_kpa": 7524.0}])
    >>> import textwrap
    >>> print(textwrap.fill(cycle_summary(c, stepped=False), 90))
    DS30 A1 t1 cycle 1: rising 8.0 kPa/s, falling 8.0 kPa/s, loop width (psi rising minus
    falling; negative: falling above) mean 45.7 deg (largest 105.8 deg at 105 kPa), area 7524
    deg kPa.  On a continuous ramp the loop holds the actuator's lag behind the pressure as
    well as its hysteresis; a stepped profile with holds (the step table) tells the two apart.
    >>> cycle_summary(c, stepped=True)[:41]
    'DS30 A1 t1 cycle 1: in steps, loop width '

    A hold that did not settle is said (customer 27: its loop width was reported without it):

    >>> s = pd.DataFrame({"from_kpa": [0.0, 160.0], "to_kpa": [160.0, 120.0],
    ...                   "note": ["", "did not settle within the hold"]})
    >>> print(textwrap.fill(cycle_summary(c, stepped=True, steps=s).split(".  ")[1], 90))
    The hold after 160 -> 120 kPa did not settle (the step table): its loop point is the
    hold's last frames, still moving.

    With several ramps in the table, each hold names its ramp:

    >>> two = s.assign(material="DS30", actuator=["A1", "A2"], trial=1, note=s["note"].iloc[1])
    >>> cycle_summary(c, stepped=True, steps=two).split(".  ")[1][:70]
    'The holds after 0 -> 160 kPa (DS30 A1 t1), 160 -> 120 kPa (DS30 A2 t1)'
    """
    text = "; ".join(
        f"{_label(c)} cycle {int(c['cycle'])}: "
        + (
            "in steps"  # a mean rate of instant steps and holds would mean little
            if stepped
            else f"rising {_fmt(c['rate_up_kpa_s'], 1)} kPa/s, falling "
            f"{_fmt(c['rate_down_kpa_s'], 1)} kPa/s"
        )
        + ", loop width (psi rising minus falling; negative: falling above) mean "
        f"{_fmt(c['width_mean_deg'], 1)} deg "
        f"(largest {_fmt(c['width_max_deg'], 1)} deg at {_fmt(c['width_max_at_kpa'], 0)} kPa), "
        f"area {_fmt(c['area_deg_kpa'], 0)} deg kPa"
        for _, c in cycles.iterrows()
    )
    moving = (
        steps[steps["note"].astype(str) == UNSETTLED]
        if steps is not None and len(steps)
        else pd.DataFrame()
    )
    if len(moving):
        several = set(RAMP_KEYS) <= set(moving.columns) and len(
            steps.groupby(list(RAMP_KEYS))  # type: ignore[union-attr]
        ) > 1
        which = ", ".join(
            f"{_fmt(r['from_kpa'], 0)} -> {_fmt(r['to_kpa'], 0)} kPa"
            + (f" ({_label(r)})" if several else "")
            for _, r in moving.iterrows()
        )
        holds = "hold after" if len(moving) == 1 else "holds after"
        its = "its loop point is" if len(moving) == 1 else "their loop points are"
        text += (
            f".  The {holds} {which} did not settle (the step table): {its} the hold's last "
            "frames, still moving."
        )
    if not stepped:  # customer 20 read a ramp's loop as the material's hysteresis alone
        text += (
            ".  On a continuous ramp the loop holds the actuator's lag behind the pressure as "
            "well as its hysteresis; a stepped profile with holds (the step table) tells the two "
            "apart."
        )
    return text


def figures(folder: Path) -> list[Figure]:
    """One page for the video dataset whose continuous tables are in ``folder`` (none if empty)."""
    folder = Path(folder)
    timeline, loops, cycles = (
        _read(folder, "timeline.csv"),
        _read(folder, "loops.csv"),
        _read(folder, "cycles.csv"),
    )
    steps, settling = _read(folder, "steps.csv"), _read(folder, "settling.csv")
    if timeline.empty:
        return []
    fig = text_page(label=f"video {folder.name}")  # A4 portrait, hand-placed axes
    fig.suptitle(
        f"Video dataset {folder.name}: every frame against the pressure log", x=0.06, ha="left"
    )
    grid = fig.add_gridspec(
        5,
        2,
        height_ratios=[1.0, 1.2, 0.15, 0.9, 0.55],
        hspace=0.5,
        wspace=0.28,
        left=0.08,
        right=0.97,
        top=0.93,
        bottom=footer_fraction(A4_PORTRAIT_IN) + 0.03,
    )
    # the time plot leaves room on its right for the pressure axis's ticks and label
    ax_t = fig.add_subplot(grid[0, :].subgridspec(1, 2, width_ratios=[0.91, 0.09], wspace=0)[0, 0])
    ax_p = ax_t.twinx()
    ramps = timeline.groupby(list(RAMP_KEYS), sort=False)
    psi_floor = float(np.nanmin(timeline["psi_deg"])) if timeline["psi_deg"].notna().any() else 0.0
    for j, (_, r) in enumerate(ramps):
        ax_t.plot(
            r["time_s"], r["psi_deg"], color=f"C{j}", lw=1.0, label=f"psi {_label(r.iloc[0])}"
        )
        bad = r[r["n_failed"] > 0]
        ax_t.plot(bad["time_s"], np.full(len(bad), psi_floor), "x", color="C3", ms=3,
                  label="failed frames" if j == 0 and len(bad) else None)
        ax_p.plot(
            r["time_s"],
            r["pressure_kpa"],
            color="0.55",
            lw=0.8,
            ls="--",
            label="setpoint" if j == 0 else None,
        )
        if r["measured_pressure_kpa"].notna().any():
            ax_p.plot(
                r["time_s"],
                r["measured_pressure_kpa"],
                color="0.3",
                lw=0.6,
                label="measured" if j == 0 else None,
            )
    if not timeline["psi_deg"].notna().any():  # nothing drawn: say why
        flagged = int(timeline["n_flagged"].sum()) if "n_flagged" in timeline.columns else 0
        ax_t.text(
            0.5, 0.5,
            f"no frame is ok: {flagged} flagged, {int(timeline['n_failed'].sum())} failed "
            "(the reasons: page 1's data quality and angles.csv)",
            transform=ax_t.transAxes, ha="center", va="center", fontsize=8.5, color="#b00000",
        )
    ax_t.set_xlabel("time on the pressure log's clock (s)")
    ax_t.set_ylabel("psi (deg)")
    ax_p.set_ylabel("pressure (kPa)")
    ax_p.grid(False)
    lines = ax_t.get_legend_handles_labels()
    more = ax_p.get_legend_handles_labels()
    # above the plot, not over it (customer 27: "best" still lay on the psi curve)
    ax_t.legend(
        lines[0] + more[0], lines[1] + more[1], loc="lower left", bbox_to_anchor=(0.0, 1.0),
        fontsize=MIN_FONT_PT, ncol=4, frameon=False, borderaxespad=0.2,
    )
    ax_t.set_title("Every frame measured (medians of short time bins)", fontsize=9, pad=16)

    ax_l = fig.add_subplot(grid[1, 0])
    for j, (key, g) in enumerate(
        loops.groupby([*RAMP_KEYS, "cycle"], sort=False)
    ):
        for direction, d in g.groupby("direction", sort=False):
            d = d.sort_values("pressure_kpa")
            # a bin whose frames are all left out (flagged) breaks the line there: no straight
            # line across pressures without data (customer 27's 120 kPa rising)
            ax_l.plot(
                d["pressure_kpa"],
                d["psi_mean_deg"].where(d["n"] > 0),
                "-" if direction == "up" else "--",
                color=f"C{j}",
                lw=1.0,
                marker="o",  # a level alone between gaps is still seen
                ms=2.5,
                label=f"{key[0]} {key[1]} t{key[2]} c{key[3]} "
                      f"{'rising' if direction == 'up' else 'falling'}",
            )
    ax_l.set_xlabel("pressure (kPa; measured when logged)")
    ax_l.set_ylabel("psi (deg)")
    ax_l.set_title("Hysteresis loops (binned by pressure)", fontsize=9)
    if len(loops):
        ax_l.legend(fontsize=MIN_FONT_PT, loc="best")

    ax_s = fig.add_subplot(grid[1, 1])
    if len(settling):
        for (key, g), j in zip(
            settling.groupby([*RAMP_KEYS, "step"], sort=False), range(10**6)
        ):
            direction = steps.loc[steps["step"] == key[3], "direction"]
            up = not len(direction) or direction.iloc[0] == "up"
            ax_s.plot(
                g["since_step_s"], g["response"], color="C0" if up else "C1", lw=0.8, alpha=0.8
            )
        ax_s.axhline(1.0, color="0.5", lw=0.6)
        ax_s.plot([], [], color="C0", label="steps up")
        ax_s.plot([], [], color="C1", label="steps down")
        ax_s.legend(fontsize=MIN_FONT_PT, loc="lower right")
        ax_s.set_title("Settling after each step", fontsize=9)
    else:
        ax_s.text(
            0.5,
            0.5,
            "no pressure steps in this recording\n(a continuous ramp)",
            ha="center",
            va="center",
            transform=ax_s.transAxes,
            fontsize=8,
        )
        ax_s.set_title("Settling after each step", fontsize=9)
    ax_s.set_xlabel("time since the step (s)")
    ax_s.set_ylabel("(psi - psi before) / change")

    ax_c = fig.add_subplot(grid[2, :])
    ax_c.axis("off")
    if len(cycles):
        ax_c.text(
            0.0, 1.0, cycle_summary(cycles, stepped=bool(len(steps)), steps=steps), va="top",
            fontsize=7,
            wrap=True, transform=ax_c.transAxes,
        )

    ax_tab = fig.add_subplot(grid[3, :])
    ax_tab.axis("off")
    if len(steps):
        shown = steps.head(MAX_TABLE_ROWS)
        cells = [
            [
                _label(s),
                str(int(s["step"])),
                f"{_fmt(s['from_kpa'], 0)} -> {_fmt(s['to_kpa'], 0)}",
                _fmt(s["change_deg"], 1),
                _fmt(s["rise_time_s"]),
                _fmt(s["overshoot_pct"], 1),
                _fmt(s["settling_time_s"]),
                _fmt(s.get("pressure_rise_time_s", np.nan)),
                str(s["note"]) if isinstance(s["note"], str) else "",
            ]
            for _, s in shown.iterrows()
        ]
        table = ax_tab.table(
            cellText=cells,
            colLabels=[
                "ramp",
                "step",
                "kPa",
                "change\n(deg)",
                "rise\n(s)",
                "overshoot\n(%)",
                "settling\n(s)",
                "pressure\nrise (s)",
                "note",
            ],
            colWidths=[0.1, 0.04, 0.08, 0.07, 0.05, 0.08, 0.07, 0.08, 0.43],
            loc="upper center",
            cellLoc="center",
        )
        table.auto_set_font_size(False)
        table.set_fontsize(MIN_FONT_PT)
        table.scale(1.0, 1.15)
        for (row, col), cell in table.get_celld().items():
            if row == 0:  # two-line headers
                cell.set_height(2 * cell.get_height())
            elif col == 8:  # the notes read from their left, inside their column
                cell.set_text_props(ha="left")
                cell.PAD = 0.02
        more_rows = len(steps) - len(shown)
        ax_tab.set_title(
            "Step responses: rise 10-90 % of the change; settling into 2 % of it (or 3 noise sd)"
            + (f"; {more_rows} more step(s) in steps.csv" if more_rows > 0 else ""),
            fontsize=8,
        )
    else:
        ax_tab.set_title("No pressure steps: no step-response figures", fontsize=8)
    strip = folder / STRIP
    if strip.is_file():
        import cv2

        img = cv2.imread(str(strip), cv2.IMREAD_COLOR)
        if img is not None:
            ax_f = fig.add_subplot(grid[4, :])
            ax_f.imshow(cv2.cvtColor(img, cv2.COLOR_BGR2RGB), interpolation="none")
            ax_f.set_axis_off()
            captions = _read(folder, STRIP_CAPTIONS)
            for k, (_, c) in enumerate(captions.iterrows()):
                ax_f.text(
                    (k + 0.5) / len(captions), -0.04, strip_caption(c), transform=ax_f.transAxes,
                    ha="center", va="top", fontsize=MIN_FONT_PT,
                )
            ax_f.set_title(
                "Frames across the recording, extracted line drawn ('measure --overlays')",
                fontsize=8,
            )
    return [fig]
