"""The command line lists every stage and explains units."""

from __future__ import annotations

import subprocess
import sys

import pandas as pd
import pytest

from pipeline.bench.cli import BENCHES
from pipeline.cli import SUBCOMMANDS

REQUIRED = {
    "synth",
    "measure",
    "aggregate",
    "model",
    "compare",
    "report",
    "acquire",
    "bench",
    "photoset",
}


def _run(*args):
    return subprocess.run(
        [sys.executable, "-m", "pipeline", *args], capture_output=True, text=True, check=False
    )


def test_help_lists_the_subcommands():
    out = _run("--help")
    assert out.returncode == 0
    for name in REQUIRED:
        assert name in out.stdout
    assert REQUIRED <= set(SUBCOMMANDS)


@pytest.mark.parametrize("name", sorted(SUBCOMMANDS))
def test_every_subcommand_has_help(name, capsys):
    """Each subcommand's module loads and its parser prints help (in this process: the fresh
    ``python -m pipeline`` process is checked by the test above and the two below)."""
    from pipeline.cli import main

    with pytest.raises(SystemExit) as stop:  # argparse exits 0 after --help
        main([name, "--help"])
    assert stop.value.code == 0
    assert f"usage: python -m pipeline {name}" in capsys.readouterr().out


def test_photoset_init_then_check(photo_folder):
    out = _run(
        "photoset",
        "init",
        str(photo_folder),
        "--pattern",
        "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg",
        "--l0-mm",
        "200",
    )
    assert out.returncode == 0, out.stderr
    assert "8 photos (6 up, 2 down)" in out.stdout
    written = (photo_folder / "photoset.yaml").read_text()
    assert "l0_mm: 200" in written and "mm_per_px" not in written  # not "mm_per_px: null"
    out = _run("photoset", "check", str(photo_folder))
    assert out.returncode == 0, out.stderr
    # warnings (no mm_per_px, an empty first photo) do not fail the check
    assert "OK (8 photos" in out.stdout


def _init_body(folder, *options: str) -> tuple[list[str], dict]:
    """``photoset init`` of ``photo_folder`` as a body set with ``options``; its args and the
    photoset.yaml it wrote."""
    import yaml

    args = ["photoset", "init", str(folder), "--pattern",
            "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg", "--l0-mm", "200",
            "--target", "body", *options]
    out = _run(*args)
    assert out.returncode == 0, out.stderr
    return args, yaml.safe_load((folder / "photoset.yaml").read_text())


def test_photoset_init_writes_a_body_sets_sealed_end(photo_folder):
    import yaml

    args, written = _init_body(photo_folder, "--mm-per-px", "0.3", "--sealed-end-mm", "6",
                               "--fixed-direction-deg", "46.5")
    assert written["sealed_end_mm"] == 6.0 and written["target"] == "body"
    assert written["fixed_direction_deg"] == 46.5
    assert "free_end" not in written and "exclude" not in written  # left to their defaults
    out = _run("photoset", "check", str(photo_folder))
    assert out.returncode == 0 and "no sealed_end_mm" not in out.stdout
    out = _run("measure", str(photo_folder), "--out", str(photo_folder.parent / "a.csv"))
    assert out.returncode == 0 and "no sealed_end_mm" not in out.stderr, out.stderr
    # a typo of its key is refused: as it was, it was ignored, and measure said nothing of it,
    # only check did (customer 47's mm_per_pix moved psi 1.4 deg, every row ok)
    written["sealed_end"] = written.pop("sealed_end_mm")
    (photo_folder / "photoset.yaml").write_text(yaml.safe_dump(written))
    for command in (
        ("photoset", "check", str(photo_folder)),
        ("measure", str(photo_folder), "--out", str(photo_folder.parent / "a.csv")),
    ):
        out = _run(*command)
        said = out.stdout + out.stderr
        assert out.returncode != 0, said
        assert "unknown key 'sealed_end', a typo of sealed_end_mm?" in said, said
        assert "(fix: rename it sealed_end_mm" in said, said
    # without it, measure says so too: every row may still come out ok (customer 14's did, 8-14
    # deg off, and only check had said it); a key far from any setting's is a warning
    written.pop("sealed_end")
    written["sealed_length"] = 6
    (photo_folder / "photoset.yaml").write_text(yaml.safe_dump(written))
    out = _run("measure", str(photo_folder), "--out", str(photo_folder.parent / "a.csv"))
    assert out.returncode == 0 and "no sealed_end_mm" in out.stderr, out.stderr
    assert "unknown key 'sealed_length' is ignored (fix: did you mean sealed_end_mm?" in out.stderr
    written.pop("sealed_length")
    written["sealed_end_mm"] = 6.0
    # without the scale it is turned into pixels with the body's length against l0_mm +
    # sealed_end_mm: check accepts it (and warns of the missing scale, as for any body)
    _run(*args, "--overwrite")
    settings = photo_folder / "photoset.yaml"
    written.pop("mm_per_px")
    settings.write_text(yaml.safe_dump(written))
    out = _run("photoset", "check", str(photo_folder))
    assert out.returncode == 0 and "no mm_per_px" in out.stderr, out.stdout + out.stderr


def test_photoset_init_names_the_empty_scene_photo_and_refuses_one_not_there(photo_folder):
    import cv2
    import numpy as np
    import yaml

    args = ["photoset", "init", str(photo_folder), "--pattern",
            "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg", "--l0-mm", "200",
            "--target", "body"]
    out = _run(*args, "--background", "empty.jpg")
    assert out.returncode == 2 and "--background empty.jpg: no such file" in out.stderr
    assert "Traceback" not in out.stderr and not (photo_folder / "manifest.csv").exists()
    cv2.imwrite(str(photo_folder / "empty.jpg"), np.full((24, 32, 3), 200, np.uint8))
    out = _run(*args, "--background", "empty.jpg")
    assert out.returncode == 0, out.stderr
    assert yaml.safe_load((photo_folder / "photoset.yaml").read_text())["background"] == "empty.jpg"
    # the empty scene is not a photo of the ramp (it does not match the pattern)
    assert "empty.jpg" not in (photo_folder / "manifest.csv").read_text()
    # a second init keeps the user's photoset.yaml and says its options were not written
    out = _run(*args, "--background", "empty.jpg", "--sealed-end-mm", "5", "--overwrite")
    assert out.returncode == 0 and "kept the existing" in out.stdout
    assert "sealed_end_mm" not in (photo_folder / "photoset.yaml").read_text()


def test_bad_input_is_one_line_without_traceback(tmp_path):
    out = _run("photoset", "init", str(tmp_path / "nope"), "--pattern", "{pressure_kpa}.jpg")
    assert out.returncode == 2
    assert "Traceback" not in out.stderr and "not a folder" in out.stderr


@pytest.mark.parametrize("what", sorted(BENCHES))
def test_every_benchmark_runs_from_the_one_entry_point(what, capsys):
    from pipeline.cli import main

    with pytest.raises(SystemExit) as stop:  # argparse exits 0 after --help
        main(["bench", what, "--help"])
    assert stop.value.code == 0
    assert f"usage: python -m pipeline bench {what}" in capsys.readouterr().out


def test_bench_model_prints_its_figures(capsys):
    from pipeline.cli import main

    assert main(["bench", "model", "--grid-sizes", "2", "4"]) == 0
    out = capsys.readouterr().out
    assert "max_rel_error" in out and "default grid (grid_n=4)" in out


def test_photoset_init_writes_a_free_end_and_exclude_boxes(photo_folder):
    # carried over from customer 26: a free strip and an exclude box had to be typed into
    # photoset.yaml by hand after init; check reads what init writes
    import yaml

    args, written = _init_body(photo_folder, "--free-end", "bends", "--exclude", "0,0,10,8",
                               "--exclude", "28,20,32,24")
    assert written["free_end"] == "bends"
    assert written["exclude"] == [[0.0, 0.0, 10.0, 8.0], [28.0, 20.0, 32.0, 24.0]]
    out = _run("photoset", "check", str(photo_folder))
    assert out.returncode == 0, out.stdout + out.stderr
    # an exclude over the whole photo: check names it (it crashed in the backdrop model), and
    # measure gives failed rows that say why instead of a traceback
    written["exclude"] = [[0, 0, 40, 30]]
    (photo_folder / "photoset.yaml").write_text(yaml.safe_dump(written))
    out = _run("photoset", "check", str(photo_folder))
    assert out.returncode != 0 and "exclude covers the whole photo" in out.stdout + out.stderr
    out = _run("measure", str(photo_folder), "--out", str(photo_folder.parent / "x.csv"))
    angles = pd.read_csv(photo_folder.parent / "x.csv")
    assert (angles["status"] == "failed").all(), out.stderr
    assert angles["reason"].str.contains("roi / exclude leave nothing of the photo").all()
    # an exclude over all of a roi says so; a roi outside the photo is told once, not twice
    for roi, exclude, said in (([4, 4, 12, 12], [[0, 0, 16, 16]], "exclude covers all of the roi"),
                               ([100, 100, 200, 200], [], "lies outside the 32x24 photo")):
        written.update(roi=roi, exclude=exclude)
        (photo_folder / "photoset.yaml").write_text(yaml.safe_dump(written))
        out = _run("photoset", "check", str(photo_folder))
        # said once for the set's 8 rows (the same problem on each row is one line)
        lines = [x for x in (out.stdout + out.stderr).splitlines() if "lines 2-9 (8 rows):" in x]
        assert out.returncode != 0 and len(lines) == 1 and said in lines[0], lines
    # a box written wrong is refused, naming the option and the form
    (photo_folder / "photoset.yaml").unlink()
    (photo_folder / "manifest.csv").unlink()
    out = _run(*args[:-2], "--exclude", "0,0,40")
    assert out.returncode != 0 and "--exclude '0,0,40': write a box's two corners" in out.stderr


def test_output_piped_into_a_reader_that_stopped_ends_without_a_traceback(photo_folder):
    # customer 34: `photoset init ... | head` ended in a BrokenPipeError traceback
    proc = subprocess.Popen(
        [sys.executable, "-m", "pipeline", "photoset", "init", str(photo_folder), "--pattern",
         "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg", "--l0-mm", "200"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()  # the reader stops before anything is printed
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141, err
    assert "Traceback" not in err and "BrokenPipeError" not in err, err
    assert (photo_folder / "manifest.csv").is_file()  # the work was done


def test_measure_out_never_replaces_a_photo_or_the_manifest(photo_folder):
    # customer 47: 'measure SET --out SET/manifest.csv' (or a photo's name) exited 0 and replaced
    # the hand-made manifest (or the photo) with angles.csv, without a word
    out = _run("photoset", "init", str(photo_folder), "--pattern",
               "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg", "--l0-mm", "200")
    assert out.returncode == 0, out.stderr
    photo = photo_folder / "DS30_A2_t1_s01_10kPa.jpg"
    kept = {p: p.read_bytes() for p in (photo_folder / "manifest.csv", photo)}
    for target in kept:
        out = _run("measure", str(photo_folder), "--out", str(target))
        assert out.returncode != 0, out.stdout
        assert f"--out {target}: exists and is not a table this command wrote" in out.stderr
        assert "Traceback" not in out.stderr
    assert {p: p.read_bytes() for p in kept} == kept
    # its own earlier table is replaced, as before
    angles = photo_folder.parent / "angles.csv"
    for _ in range(2):
        out = _run("measure", str(photo_folder), "--out", str(angles))
        assert out.returncode == 0, out.stderr
    # nor does a later stage's --out replace a person's file (the review: they had no guard)
    hysteresis = photo_folder.parent / "hysteresis.csv"
    out = _run("aggregate", str(angles), "--out", str(hysteresis))
    assert out.returncode == 0, out.stderr
    for command in (("aggregate", str(angles)), ("report", "--angles", str(angles)),
                    ("compare", str(hysteresis))):
        for target in kept:
            out = _run(*command, "--out", str(target))
            assert out.returncode != 0, out.stdout
            assert f"--out {target}: exists and is not a" in out.stderr, out.stderr
    assert {p: p.read_bytes() for p in kept} == kept
    # an angles.csv put where the manifest was is named as such (measure stopped in a TypeError)
    (photo_folder / "manifest.csv").write_bytes(angles.read_bytes())
    for command in (("photoset", "check", str(photo_folder)),
                    ("measure", str(photo_folder), "--out", str(angles))):
        out = _run(*command)
        said = out.stdout + out.stderr
        assert out.returncode != 0 and "Traceback" not in said, said
        assert "is a table of measured angles (its header has psi_deg and status" in said, said


def test_a_manifest_column_spelt_almost_as_a_setting_is_refused_as_a_typo(photo_folder):
    # customer 47: a column 'postive_turn' holding cw was carried as a column of its own, and
    # every row came out ok with the sign it had not asked for; check said OK
    out = _run("photoset", "init", str(photo_folder), "--pattern",
               "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg", "--l0-mm", "200")
    assert out.returncode == 0, out.stderr
    manifest = pd.read_csv(photo_folder / "manifest.csv")
    manifest.assign(postive_turn="cw").to_csv(photo_folder / "manifest.csv", index=False)
    for command in (("photoset", "check", str(photo_folder)),
                    ("measure", str(photo_folder), "--out", str(photo_folder.parent / "a.csv"))):
        out = _run(*command)
        said = out.stdout + out.stderr
        assert out.returncode != 0, said
        assert "manifest.csv line 1: column 'postive_turn', a typo of positive_turn?" in said
        assert "(fix: rename it positive_turn" in said
    # a column of the user's own is carried as before; one named as angles.csv's own (the
    # review: 'reason' was left out without a word) as manifest_<name>
    manifest.assign(operator="Ann", reason="retaken").to_csv(photo_folder / "manifest.csv",
                                                             index=False)
    out = _run("measure", str(photo_folder), "--out", str(photo_folder.parent / "a.csv"))
    assert out.returncode == 0, out.stderr
    angles = pd.read_csv(photo_folder.parent / "a.csv")
    assert (angles["operator"] == "Ann").all() and (angles["manifest_reason"] == "retaken").all()
    assert list(angles.columns).count("reason") == 1
