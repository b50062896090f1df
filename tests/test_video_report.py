"""The report page of a video dataset: one page per dataset, its figures and tables named."""

from __future__ import annotations

import numpy as np
import pypdfium2 as pdfium

from pipeline.layout.style import report_style
from pipeline.report.build import build_report, report_figures
from pipeline.report.data import Dataset, ReportInputs, load_report_data
from pipeline.video.continuous import write_continuous
from pipeline.video.pages import figures, write_strip


def _text(pdf_path) -> list[str]:
    doc = pdfium.PdfDocument(str(pdf_path))
    return [doc[i].get_textpage().get_text_range() for i in range(len(doc))]


def test_one_page_per_video_dataset_with_its_step_table(measured, tmp_path):
    angles = tmp_path / "angles.csv"
    measured.to_csv(angles, index=False)
    for name in ("steps_a", "steps_b"):
        write_continuous(measured, tmp_path / "continuous" / name)
    base = ReportInputs(datasets=(Dataset("steps", angles),), title="t")
    with report_style():  # the pages of the report without the video folders, drawn, not saved
        plain, _ = report_figures(load_report_data(base))
    with_video = build_report(
        ReportInputs(
            datasets=base.datasets,
            title="t",
            video_dirs=(tmp_path / "continuous" / "steps_a", tmp_path / "continuous" / "steps_b"),
        ),
        tmp_path / "video.pdf",
    )
    assert with_video.pages == len(plain) + 2
    pages = _text(tmp_path / "video.pdf")
    assert "0 photos, 135 video frames" in pages[0]  # not "135 photos"
    # a point of one video trial is its frames' mean, not "one photo alone" (customer 27)
    joined = " ".join(" ".join(pages).split())
    assert "hollow points: one video trial (its frames' mean) alone (n = 1)" in joined
    assert "one photo alone" not in joined
    # the contents name the video pages (customer 20 found them missing), at the first one
    first = 1 + next(i for i, p in enumerate(pages) if "Video dataset" in p)
    assert f"p. {first} One page per video: every frame, loops, steps" in " ".join(
        pages[0].split()
    )
    # the provenance page says what those pages are in words, not '--video-dirs' (customer 20)
    assert "1 page(s) of a video dataset from" in " ".join(pages[-1].split())
    video_pages = [p for p in pages if "Video dataset" in p]
    assert len(video_pages) == 2 and "Video dataset steps_a" in video_pages[0]
    for text in video_pages:
        assert "Step responses" in text and "40 -> 80" in text and "loop width" in text
    assert not any("pipeline.video.pages" in w for w in with_video.warnings)


def test_a_folder_without_tables_gives_no_page_and_a_strip_needs_overlays(measured, tmp_path):
    assert figures(tmp_path / "empty") == []
    assert write_strip(measured, tmp_path / "no-overlays", tmp_path) is None
    write_continuous(measured.assign(psi_deg=np.nan, status="failed"), tmp_path / "all_failed")
    assert len(figures(tmp_path / "all_failed")) == 1  # every frame failed: the page still says so
    # every frame flagged (a whole set measured without its fixed end): the plot was empty and
    # the step table said "too few frames around the step", never why
    from pipeline.report.textcheck import drawn_texts

    write_continuous(measured.assign(status="flagged"), tmp_path / "all_flagged")
    with report_style():
        (fig,) = figures(tmp_path / "all_flagged")
        said = [t.text for t in drawn_texts(fig)]
    assert [t for t in said if t.startswith("no frame is ok: 135 flagged, 0 failed")], said


def test_video_pages_have_no_overlaps_no_small_fonts_nothing_on_the_footer(measured, tmp_path):
    from pipeline.layout.style import FOOTER_PT, MIN_FONT_PT
    from pipeline.report.textcheck import FOOTER_GID, drawn_texts, outside_page, overlapping_texts

    write_continuous(measured, tmp_path / "continuous" / "steps")
    with report_style():
        figs = figures(tmp_path / "continuous" / "steps")
        assert figs
        for fig in figs:
            texts = drawn_texts(fig)
            assert len(texts) > 5
            assert overlapping_texts(texts) == []
            assert outside_page(texts) == []  # customer 20: the pressure axis's ticks were cut
            assert [(t.text, t.size_pt) for t in texts if t.size_pt < MIN_FONT_PT] == []
            on_footer = [
                t.text for t in texts if t.gid != FOOTER_GID and t.box.y0 < FOOTER_PT - 0.5
            ]
            assert on_footer == []


def test_the_photo_strip_of_a_video_shows_its_frames(video_set, measured, tmp_path):
    # a customer's report said "photo not found" under every tile of a video's strip: it looked
    # for the video's name as an overlay and as a photo; now each tile is a frame's overlay (a
    # few per video are drawn), else the frame read from the video
    import shutil

    from pipeline.photoset_measure import measure_photoset
    from pipeline.report.strip import build_strip

    angles = tmp_path / "angles.csv"
    measured.to_csv(angles, index=False)
    raw = load_report_data(
        ReportInputs(datasets=(Dataset("steps", angles, photoset_dir=video_set),), title="t")
    )
    strip = build_strip(raw, "SS40")
    assert strip is not None and len(strip.photos) >= 4
    assert all(p.image is not None and p.source == "raw" for p in strip.photos)
    folder = tmp_path / "set"
    shutil.copytree(video_set, folder)
    drawn = measure_photoset(folder, jobs=1, overlays_dir=tmp_path / "ov")
    drawn.to_csv(angles, index=False)
    data = load_report_data(
        ReportInputs(
            datasets=(Dataset("steps", angles, photoset_dir=folder, overlays_dir=tmp_path / "ov"),),
            title="t",
        )
    )
    strip = build_strip(data, "SS40")
    assert strip is not None and all(p.source == "overlay" for p in strip.photos)


def test_the_step_tables_headers_and_notes_stay_inside_their_cells(measured, tmp_path):
    # customer 27: a note ("0 of the last 12 frames of the hold are ok: no final value") ran past
    # the table's border and the headers "overshoot (%" and "pressure rise (s" were cut off
    import matplotlib as mpl
    import pandas as pd
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from pipeline.video.continuous import UNSETTLED

    folder = tmp_path / "continuous" / "steps"
    write_continuous(measured, folder)
    steps = pd.read_csv(folder / "steps.csv")
    notes = [
        "no value before it: no ok frame ends the hold before",  # the longest step_response gives
        "no final value: 123 of the hold's last 456 frames ok",
        "too few ok frames after the step (4)",
        UNSETTLED,
    ]
    steps = pd.concat([steps] * 2, ignore_index=True).head(len(notes)).assign(note=notes)
    steps.to_csv(folder / "steps.csv", index=False)
    with report_style():
        (fig,) = figures(folder)
        canvas = FigureCanvasAgg(fig)
        with mpl.rc_context({"text.hinting": "no_hinting"}):  # as the PDF draws its glyphs
            canvas.draw()
        renderer = canvas.get_renderer()
        (table,) = [t for ax in fig.axes for t in ax.tables]
        cells = table.get_celld()
        assert {cells[row, 8].get_text().get_text() for row in range(1, 5)} == set(notes)
        for (row, col), cell in cells.items():
            box = cell.get_window_extent(renderer)
            text = cell.get_text().get_window_extent(renderer)
            assert box.x0 <= text.x0 and text.x1 <= box.x1, (row, col, cell.get_text().get_text())
            assert box.y0 <= text.y0 and text.y1 <= box.y1, (row, col, cell.get_text().get_text())


def test_page_one_says_a_crossing_is_coarse_because_the_frames_between_were_flagged():
    # customer 27: every frame at 120 kPa rising was flagged (the tip out of the picture), and
    # page 1 asked for "smaller pressure steps" than the 40 kPa taken
    import pandas as pd

    from pipeline.report.summary import coarse_crossing_notes

    levels = [(0, 210.0), (40, 180.0), (80, 130.0), (120, 10.0), (160, -140.0)]
    rows = [
        {"dataset": "vid", "image": "v.avi", "frame": 10 * i + k, "material": "DS30",
         "actuator": "A3", "trial": 1, "direction": "up", "pressure_kpa": float(p),
         "step": i, "since_step_s": 0.1 * k if i else float("nan"),
         "psi_deg": psi, "status": "flagged" if p == 120 else "ok",
         "reason": "body touches the image border at its free end: the tip may be outside"
         if p == 120 else ""}
        for i, (p, psi) in enumerate(levels)
        for k in range(10)
    ]
    (note,) = coarse_crossing_notes(pd.DataFrame(rows))
    assert "between 80 and 160 kPa rising" in note
    # the end of its hold: the settled frames, the last 3 of its 10 (SETTLED_MIN_FRAMES)
    assert "the 3 frames ending the hold at 120 kPa between them are not in the curve" in note
    # a video ramped continuously has no holds: its frames at those pressures (the review's)
    (ramp,) = coarse_crossing_notes(pd.DataFrame(rows).assign(since_step_s=float("nan")))
    assert "the 10 frames at 120 kPa between them are not in the curve" in ramp
    assert "(flagged: body's tip at the image border, 3)" in note
    assert "smaller pressure steps" not in note and "reasons in angles.csv" in note
    # the same frames ok: the jump is between 120 and 160 kPa, with nothing between them
    (note,) = coarse_crossing_notes(pd.DataFrame(rows).assign(status="ok"))
    assert "between 120 and 160 kPa rising" in note
    assert "(take smaller pressure steps there)" in note
