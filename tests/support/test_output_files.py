"""The command line's output files (``qrrt_circuits._support.output_files``): checked before the work without
changing anything, written whole after it, and written in place wherever a rename would lose
something."""

import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from qrrt_circuits._support import available_memory as probe
from qrrt_circuits._support import output_files
from qrrt_circuits._support.output_files import check_output_file, same_file, write_replacing


def _names(folder: Path) -> list[str]:
    return sorted(path.name for path in folder.iterdir())


def _failing(handle):
    handle.write("partial")
    raise OSError(errno.ENOSPC, "No space left on device")


def test_a_failed_write_leaves_the_old_file_and_no_temporary_file(tmp_path):
    target = tmp_path / "out.json"
    target.write_text("old")
    with pytest.raises(OSError):
        write_replacing(target, _failing)
    assert target.read_text() == "old" and _names(tmp_path) == ["out.json"]


def test_a_replaced_file_keeps_its_mode_and_its_symbolic_link(tmp_path):
    target = tmp_path / "out.json"
    target.write_text("old")
    target.chmod(0o604)  # a mode no usual umask gives a new file
    link = tmp_path / "link.json"
    link.symlink_to(target)
    write_replacing(link, lambda handle: handle.write("new"))
    assert link.is_symlink() and target.read_text() == "new" and target.stat().st_mode & 0o777 == 0o604
    assert _names(tmp_path) == ["link.json", "out.json"]


def test_hard_links_are_written_in_place_and_a_failure_says_the_file_may_be_partial(tmp_path):
    target = tmp_path / "m.json"
    target.write_text("old")
    (tmp_path / "hard.json").hardlink_to(target)
    write_replacing(target, lambda handle: handle.write("new"))
    assert (tmp_path / "hard.json").read_text() == "new" and target.stat().st_nlink == 2
    with pytest.raises(OSError, match="written in place, so the file may be left partial"):
        write_replacing(target, _failing)


def test_a_long_name_fits_the_temporary_name(tmp_path):
    long_name = tmp_path / ("a" * 245 + ".json")
    write_replacing(long_name, lambda handle: handle.write("{}"))
    assert long_name.read_text() == "{}" and _names(tmp_path) == [long_name.name]


def test_a_refused_rename_or_temporary_file_falls_back_to_writing_in_place(tmp_path, monkeypatch):
    """A sticky folder or a bind mount refuses the rename (EPERM, EBUSY); a folder that takes no new
    file refuses the temporary file: the file was checked writable, so it is written in place."""
    target = tmp_path / "out.json"
    target.write_text("old")

    def refused(*args, **kwargs):
        raise PermissionError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(output_files.os, "replace", refused)
    write_replacing(target, lambda handle: handle.write("renamed"))
    assert target.read_text() == "renamed" and _names(tmp_path) == ["out.json"]
    monkeypatch.undo()
    monkeypatch.setattr(output_files.tempfile, "mkstemp", refused)
    write_replacing(target, lambda handle: handle.write("in place"))
    assert target.read_text() == "in place" and _names(tmp_path) == ["out.json"]


def test_json_to_a_redirected_standard_output_follows_what_it_holds(tmp_path):
    """``--json /dev/stdout > log`` writes the JSON through the standard output, after the metrics
    (opening /dev/stdout again truncated the log and the later lines landed inside the JSON)."""
    log = tmp_path / "log.txt"
    with log.open("w") as out:
        run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "rrt",
                              "--max-nodes", "3", "--json", "/dev/stdout"], stdout=out, stderr=subprocess.PIPE,
                             text=True, cwd=tmp_path, timeout=120)
    assert run.returncode == 0, run.stderr
    text = log.read_text()
    start = text.index("\n{") + 1
    result, end = json.JSONDecoder().raw_decode(text[start:])
    assert "metrics:" in text[:start] and result["status"] == "max_nodes"
    assert text[start + end:].strip() == "wrote /dev/stdout"


def test_the_check_changes_nothing_it_finds(tmp_path):
    """A dangling link keeps pointing where it did (the check removed the link and left an empty
    file at its target); a new path is left absent; an existing file keeps its content."""
    link = tmp_path / "link.json"
    link.symlink_to(tmp_path / "missing" / "target.json")
    (tmp_path / "missing").mkdir()
    check_output_file(str(link), "--json")
    assert link.is_symlink() and not (tmp_path / "missing" / "target.json").exists()
    check_output_file(str(tmp_path / "new.json"), "--json")
    assert not (tmp_path / "new.json").exists()
    kept = tmp_path / "kept.json"
    kept.write_text("old")
    check_output_file(str(kept), "--json")
    assert kept.read_text() == "old"


@pytest.mark.parametrize("path, message", [("", "must name a file"), ("-", "must name a file"),
                                           ("nowhere/x.json", "does not exist")])
def test_paths_refused_before_the_work(tmp_path, path, message):
    with pytest.raises(ValueError, match=message):
        check_output_file(path if not path.startswith("nowhere") else str(tmp_path / path), "--json")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_a_pipe_is_checked_without_opening_it(tmp_path):
    """Opening a pipe blocks until a reader comes, and hands a waiting reader an end of file: the
    check only asks for write permission (run in a child, so a regression cannot hang the suite)."""
    pipe = tmp_path / "out.json"
    os.mkfifo(pipe)
    code = ("from qrrt_circuits._support.output_files import check_output_file; "
            f"check_output_file({str(pipe)!r}, '--json')")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


def test_same_file_through_a_hard_link(tmp_path):
    first = tmp_path / "a.png"
    first.write_text("x")
    (tmp_path / "b.png").hardlink_to(first)
    assert same_file(str(first), str(tmp_path / "b.png"))
    assert same_file(str(first), str(tmp_path / "." / "a.png"))
    assert not same_file(str(first), str(tmp_path / "c.png"))
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--json", "a.png", "--plot", "b.png"],
                         capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert run.returncode == 2 and "name the same file" in run.stderr


def test_an_append_only_file_is_refused_before_the_work(tmp_path):
    """An append-only file (chattr +a) opened for appending passed the check; the write, which must
    replace it, then failed after the plan."""
    target = tmp_path / "log.json"
    target.write_text("old")
    try:
        made = subprocess.run(["chattr", "+a", str(target)], capture_output=True)
    except FileNotFoundError:  # no chattr
        made = None
    if made is None or made.returncode != 0:
        pytest.skip("chattr +a is not available here (needs root and a file system with attributes)")
    try:
        with pytest.raises(ValueError, match="cannot be written"):
            check_output_file(str(target), "--json")
        assert target.read_text() == "old"
    finally:
        subprocess.run(["chattr", "-a", str(target)], capture_output=True)


def _plan(argv, tmp_path, **streams):
    return subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "rrt", "--max-nodes", "3",
                           *argv], text=True, cwd=tmp_path, timeout=120, **streams)


def test_an_inherited_descriptor_is_written_after_what_it_holds(tmp_path):
    """``--json /dev/fd/3 3>>log`` appended nothing: /dev/fd/3 was opened again and truncated."""
    log = tmp_path / "log"
    log.write_text("earlier line\n")
    run = subprocess.run(["sh", "-c", 'exec "$0" -m qrrt_circuits.cli plan --planner rrt --max-nodes 3 '
                                      '--json /dev/fd/3 3>>"$1"', sys.executable, str(log)],
                         capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert run.returncode == 0, run.stderr
    text = log.read_text()
    assert text.startswith("earlier line\n") and json.loads(text[len("earlier line\n"):])["status"] == "max_nodes"


def test_paths_that_would_clash_or_name_nothing_are_refused_before_the_work(tmp_path):
    with (tmp_path / "f.json").open("w") as out:  # --json f.json > f.json: the two would overwrite each other
        run = _plan(["--json", "f.json"], tmp_path, stdout=out, stderr=subprocess.PIPE)
    assert run.returncode == 2 and "is the file the standard output goes to" in run.stderr
    run = _plan(["--json", str(tmp_path / "newdir") + "/"], tmp_path, capture_output=True)
    assert run.returncode == 2 and "names a folder (it ends in a slash)" in run.stderr
    assert not (tmp_path / "newdir").exists()
    run = _plan(["--json", "/dev/fd/9"], tmp_path, capture_output=True)
    assert run.returncode == 2 and "names descriptor 9, which is not open" in run.stderr


def test_a_file_of_another_group_in_a_set_group_id_folder_is_replaced_whole(tmp_path, monkeypatch):
    """A rename keeps a set-group-ID folder's group, so such a file is not written in place."""
    folder = tmp_path / "shared"
    folder.mkdir()
    folder.chmod(0o2775)
    target = folder / "out.json"
    target.write_text("old")
    real_getegid = os.getegid
    monkeypatch.setattr(output_files.os, "getegid", lambda: real_getegid() + 1)  # "another group"
    assert not output_files._write_in_place(target)
    folder.chmod(0o775)
    assert output_files._write_in_place(target)


def test_the_to_dict_output_can_be_counted_before_a_plan(monkeypatch):
    """``to_dict``'s lists take about as much memory as the tree: a caller that writes them can
    have them counted (``output_bytes_per_node``), and a plan that fits alone is then refused."""
    from qrrt_circuits._support.memory import JSON_BYTES_PER_COORDINATE, JSON_BYTES_PER_NODE, check_plan_fits

    monkeypatch.setattr(probe, "available_memory", lambda: (300 << 20, probe.MACHINE_SOURCE))
    check_plan_fits(10**6, 4096, 20000, 2)  # the plan alone: about 188 MiB
    with pytest.raises(ValueError, match="its JSON output"):
        check_plan_fits(10**6, 4096, 20000, 2,
                        output_bytes_per_node=JSON_BYTES_PER_NODE + 2 * JSON_BYTES_PER_COORDINATE)


def test_a_plan_too_large_for_memory_is_refused_before_it_runs_and_json_adds_nothing(tmp_path, monkeypatch, capsys):
    """``qrrt plan --json``: the plan's own check refuses limits whose tree could exceed the
    available memory, before the plan and before any output file exists; the streamed JSON is not
    charged per node (``PlanResult.write_json``)."""
    from qrrt_circuits.cli import main

    monkeypatch.setattr(probe, "available_memory", lambda: (300 << 20, probe.MACHINE_SOURCE))
    with pytest.raises(SystemExit) as exited:  # a tree of about 380 MiB (above always_fits_bytes)
        main(["plan", "--planner", "prrt", "--workers", "4096", "--max-nodes", "2000000",
              "--json", str(tmp_path / "out.json")])
    assert exited.value.code == 2
    err = capsys.readouterr().err
    assert "max_nodes = 2000000: this plan could need about" in err and "JSON output" not in err
    assert not (tmp_path / "out.json").exists()
