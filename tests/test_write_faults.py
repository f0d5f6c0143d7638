"""A full disk and a read-only folder, as a user meets them: one line, never a file that looks finished.

The cases run on a small file system of their own (tmpfs of 2 MB, mounted for the test): it
is filled to leave a command room for part of its files, so the command fails part-way
through writing, as on a nearly full disk. Mounting needs root (or CAP_SYS_ADMIN); where the
machine does not allow it the tests are skipped with the reason.
"""

from __future__ import annotations

import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from clearance.cli import main

ARM = (
    '<mujoco><worldbody><body name="arm"><joint name="elbow" axis="0 0 1"/>'
    '<geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/></body></worldbody>'
    '<actuator><motor joint="elbow"/></actuator></mujoco>'
)


def _call(argv: list[str], capsys) -> tuple[int, str, str]:
    try:
        rc = main(argv)
    except SystemExit as stop:
        rc = stop.code
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture
def disk(tmp_path) -> Iterator[Path]:
    """A 2 MB tmpfs mounted at ``tmp_path/disk`` for the test."""
    mnt = tmp_path / "disk"
    mnt.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mnt)], capture_output=True, text=True)
    if done.returncode:
        pytest.skip(f"cannot mount a small file system here ({done.stderr.strip() or 'mount failed'}; needs root)")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


def _fill(mnt: Path, leave: int) -> None:
    """Fill the file system at ``mnt`` so that about ``leave`` bytes stay free."""
    import os

    st = os.statvfs(mnt)
    free = st.f_bavail * st.f_frsize
    (mnt / "filler").write_bytes(b"\0" * max(0, free - leave))


def _pages(f: Path) -> int:
    """Bytes a file takes on a tmpfs: whole 4 KiB pages."""
    return -(-f.stat().st_size // 4096) * 4096


def _size(folder: Path) -> int:
    """Bytes the files under ``folder`` take on a tmpfs."""
    return sum(_pages(f) for f in folder.rglob("*") if f.is_file())


def _assert_one_fault_line(rc, err: str, folder: Path) -> None:
    assert rc == 1, err  # a fault during the work, not a refusal of the input
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("error: cannot write ") and "No space left on device" in lines[0], lines[0]
    assert str(folder) in lines[0], lines[0]


def test_run_into_a_full_disk_leaves_no_file_that_looks_finished(disk, tmp_path, capsys):
    argv = ["run", "--duration-ms", "3", "--no-progress"]
    # 3 ms of the default run: about 1 MB of files, the arrays 0.6 MB of it
    whole = tmp_path / "whole"
    assert _call([*argv, "--out", str(whole)], capsys)[0] == 0
    arrays = _pages(whole / "result.npz") + _pages(whole / "ideal.npz")
    out = disk / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    # room for the arrays and half of the rest: the command fails among its report's files
    _fill(disk, arrays + (_size(whole) - arrays) // 2)
    rc, _, err = _call([*argv, "--out", str(out)], capsys)
    _assert_one_fault_line(rc, err, out)
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]  # the user's file stays, nothing of the run
    assert sorted(p.name for p in disk.iterdir()) == ["filler", "out"]  # no private folder left behind


def test_retrofit_into_a_full_disk_leaves_no_file_that_looks_finished(disk, tmp_path, capsys):
    (tmp_path / "arm.xml").write_text(ARM)
    argv = ["retrofit", str(tmp_path / "arm.xml"), "--joint", "elbow", "--contact-mode", "exact", "--no-speed"]
    whole = tmp_path / "whole"
    rc, _, err = _call([*argv, "--out", str(whole)], capsys)
    assert rc == 0, err
    out = disk / "r"
    _fill(disk, _size(whole) // 2)  # room for half of its files
    rc, _, err = _call([*argv, "--out", str(out)], capsys)
    _assert_one_fault_line(rc, err, out)
    assert not out.exists() or not list(out.iterdir())
    assert sorted(p.name for p in disk.iterdir()) in (["filler"], ["filler", "r"])


def test_allocate_into_a_full_disk_keeps_its_runs_and_writes_no_report(disk, capsys):
    out = disk / "a"
    _fill(disk, 5 * 4096)  # the lock and a few run records, not the whole store
    argv = ["allocate", "--joints", "crank_rod", "rod_slider", "--budget", "150", "--rpm", "3000", "--runs", "2"]
    rc, _, err = _call([*argv, "--periods", "2", "--workers", "1", "--out", str(out), "--no-progress"], capsys)
    _assert_one_fault_line(rc, err, out)
    assert not (out / "allocation.md").exists()
    # what is kept is whole: each run record reads (a resumed command uses them)
    import json

    for record in (out / "runs").glob("run_*.json"):
        json.loads(record.read_text())


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "--duration-ms", "0.3"],
        ["allocate", "--budget", "100"],
        ["retrofit", "{arm}", "--joint", "elbow"],
    ],
    ids=["run", "allocate", "retrofit"],
)
def test_a_read_only_folder_is_refused_before_any_work(argv, disk, tmp_path, capsys):
    (tmp_path / "arm.xml").write_text(ARM)
    done = subprocess.run(["mount", "-o", "remount,ro", str(disk)], capture_output=True, text=True)
    if done.returncode:
        pytest.skip(f"cannot make the small file system read-only here ({done.stderr.strip()})")
    out = disk / "out"
    rc, stdout, err = _call([a.replace("{arm}", str(tmp_path / "arm.xml")) for a in argv] + ["--out", str(out)], capsys)
    assert rc == 2 and "Traceback" not in err, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and f"--out {out}" in lines[0] and "Read-only file system" in lines[0], err
    assert stdout == ""  # refused before anything was prepared or simulated
