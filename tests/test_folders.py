"""Folders written whole (staged_folder); a digest that changes exactly when a folder's bytes do."""

from __future__ import annotations

import os

import pytest

from pipeline import folders
from pipeline.errors import UserInputError
from pipeline.folders import staged_folder, update_folder_digest


def test_staged_folder_replaces_a_previous_output_only_when_complete(tmp_path):
    final = tmp_path / "set"
    with staged_folder(final, marker="truth.csv") as tmp:
        (tmp / "truth.csv").write_text("v1")
        assert not final.exists() and tmp.name == ".set.partial"
    assert (final / "truth.csv").read_text() == "v1"
    with pytest.raises(KeyboardInterrupt), staged_folder(final, marker="truth.csv") as tmp:
        (tmp / "truth.csv").write_text("v2")
        raise KeyboardInterrupt
    assert (final / "truth.csv").read_text() == "v1"  # the interrupted write left the old set alone
    assert sorted(p.name for p in tmp_path.iterdir()) == ["set"]  # and no partial folder
    with staged_folder(final, marker="truth.csv") as tmp:
        (tmp / "truth.csv").write_text("v3")
    assert (final / "truth.csv").read_text() == "v3"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["set"]


def test_staged_folder_clears_what_a_killed_run_left_and_never_replaces_a_users_folder(tmp_path):
    final = tmp_path / "set"
    (tmp_path / ".set.partial").mkdir()
    (tmp_path / ".set.partial" / "half.jpg").write_bytes(b"x")  # left by a SIGKILL
    with staged_folder(final, marker="truth.csv") as tmp:
        assert list(tmp.iterdir()) == []
        (tmp / "truth.csv").write_text("ok")
    photos = tmp_path / "photos"
    photos.mkdir()
    (photos / "IMG_0001.jpg").write_bytes(b"raw data")
    with (
        pytest.raises(UserInputError, match="not an output of this command"),
        staged_folder(photos, marker="truth.csv"),
    ):
        pass
    assert (photos / "IMG_0001.jpg").read_bytes() == b"raw data"
    assert not (tmp_path / ".photos.partial").exists()


def _photos(folder):
    folder.mkdir()
    files = {"a.jpg": b"photo a", "b.jpg": b"photo b", "manifest.csv": b"image\na.jpg\nb.jpg\n"}
    for name, data in files.items():
        (folder / name).write_bytes(data)
    return folder


@pytest.mark.parametrize(
    "change", ["replace", "add", "remove", "rename", "edit manifest", "same size"]
)
def test_digest_changes_with_the_bytes_of_any_file(tmp_path, change):
    folder = _photos(tmp_path / "set")
    digest = update_folder_digest(folder, tmp_path / "d" / "set.sha256")
    before = digest.read_text()
    if change == "replace":
        (folder / "a.jpg").write_bytes(b"a fixed photo")
    elif change == "add":
        (folder / "c.jpg").write_bytes(b"photo c")
    elif change == "remove":
        (folder / "b.jpg").unlink()
    elif change == "rename":
        (folder / "b.jpg").rename(folder / "c.jpg")
    elif change == "edit manifest":
        (folder / "manifest.csv").write_bytes(b"image\na.jpg\n")
    else:  # same size, same mtime: only the content tells
        st = (folder / "a.jpg").stat()
        (folder / "a.jpg").write_bytes(b"photo A")
        os.utime(folder / "a.jpg", ns=(st.st_atime_ns, st.st_mtime_ns))
    assert update_folder_digest(folder, digest).read_text() != before


def test_digest_covers_the_files_outside_the_folder_that_the_set_names(tmp_path):
    from pipeline.photoset import referenced_files

    folder = _photos(tmp_path / "set")
    (tmp_path / "empty.png").write_bytes(b"the empty scene")
    (folder / "photoset.yaml").write_text("l0_mm: 200\n")
    (folder / "manifest.csv").write_text("image,background\na.jpg,../empty.png\nb.jpg,\n")
    assert referenced_files(folder) == ((tmp_path / "empty.png").resolve(),)
    digest = update_folder_digest(folder, tmp_path / "d" / "set.sha256", referenced_files(folder))
    before = digest.read_text()
    assert str((tmp_path / "empty.png").resolve()) in before
    (tmp_path / "empty.png").write_bytes(b"the empty scene, re-taken")
    assert update_folder_digest(folder, digest, referenced_files(folder)).read_text() != before


def test_digest_covers_photos_shared_from_a_folder_outside_the_set(tmp_path):
    # customer 45: three actuators in one view, one set each, the photos in one shared folder
    # named as ../photos/x.jpg: a photo re-taken there left "Nothing to be done" and a stale psi
    from pipeline.photoset import referenced_files

    folder = _photos(tmp_path / "A1")
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "t1.jpg").write_bytes(b"photo 1")
    (folder / "photoset.yaml").write_text("l0_mm: 200\n")
    (folder / "manifest.csv").write_text("image\n../photos/t1.jpg\na.jpg\n../photos/gone.jpg\n")
    assert referenced_files(folder) == ((tmp_path / "photos" / "t1.jpg").resolve(),)
    digest = update_folder_digest(folder, tmp_path / "d" / "A1.sha256", referenced_files(folder))
    before = digest.read_text()
    (tmp_path / "photos" / "t1.jpg").write_bytes(b"photo 1, re-taken")
    assert update_folder_digest(folder, digest, referenced_files(folder)).read_text() != before


def test_digest_covers_a_videos_log_and_frames_named_from_outside_the_set(tmp_path):
    # a video set naming its pressure log and a frame sequence in folders beside it: only the
    # video itself was watched (the review of the change above)
    from pipeline.photoset import referenced_files

    folder = tmp_path / "set"
    folder.mkdir()
    for name in ("logs/p.csv", "frames/f_0001.jpg", "frames/f_0002.jpg", "videos/v.mp4"):
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_bytes(name.encode())
    (folder / "manifest.csv").write_text(
        "video,pressure_log,material,actuator,trial\n"
        "../frames/f_%04d.jpg,../logs/p.csv,DS20,A1,1\n../videos/v.mp4,../logs/p.csv,DS20,A1,2\n"
    )
    assert [p.relative_to(tmp_path).as_posix() for p in referenced_files(folder)] == [
        "frames/f_0001.jpg", "frames/f_0002.jpg", "logs/p.csv", "videos/v.mp4"
    ]


def test_digest_is_rewritten_only_when_it_changes_and_reads_only_changed_files(
    tmp_path, monkeypatch
):
    folder = _photos(tmp_path / "set")
    (folder / ".DS_Store").write_bytes(b"finder")  # hidden files are not photos
    digest = update_folder_digest(folder, tmp_path / "d" / "set.sha256")
    os.utime(digest, ns=(1, 1))
    reads = []
    real = folders._sha256
    monkeypatch.setattr(folders, "_sha256", lambda path: reads.append(path.name) or real(path))
    os.utime(folder / "a.jpg")  # touched: same bytes
    (folder / ".DS_Store").write_bytes(b"finder again")
    update_folder_digest(folder, digest)
    assert digest.stat().st_mtime_ns == 1  # untouched, so Snakemake re-runs nothing
    assert reads == ["a.jpg"]  # only the file whose stat changed was read again
    (folder / "b.jpg").write_bytes(b"photo B!")
    update_folder_digest(folder, digest)
    assert digest.stat().st_mtime_ns > 1 and reads == ["a.jpg", "b.jpg"]
