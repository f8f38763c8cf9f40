"""``qrrt reproduce`` on a full disk: no file left partial, one line naming the file, a re-run resumes.

The run writes into a small tmpfs (mounted in a private mount namespace with ``unshare``) that a
filler file leaves only a few pages free, for each number of free pages from none to enough for
the whole run, so the disk fills at each write of the run in turn (settings, records, the figure,
the summary). Where the machine allows no private mount, the file size limit (``RLIMIT_FSIZE``)
makes the writes fail instead, at sizes from 100 bytes to the largest file of the run.

After each failure: ``settings.json`` and ``summary.json`` are absent or whole (strict JSON), every
figure is absent or a whole PNG, ``records.csv`` holds only whole records apart from a last line
the next run sets aside; the error is one line naming the file; and the same command, once the
filler is gone, finishes with the uninterrupted run's ``summary.json``, byte for byte.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import textwrap

import pytest
from summaries import results_of

COMMAND = ["reproduce", "corridor", "--quick", "--trials", "1", "--no-progress"]
PAGE = 4096

SCENARIO = textwrap.dedent('''
    """Runs inside the private mount namespace (or under RLIMIT_FSIZE); prints JSON lines."""
    import json, os, resource, signal, subprocess, sys
    from pathlib import Path

    disk, mode, sizes, command = Path(sys.argv[1]), sys.argv[2], json.loads(sys.argv[3]), json.loads(sys.argv[4])

    def run(out, limit=None):
        def preexec():
            if limit is not None:
                signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG
                resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
        done = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", *command, "--out", str(out)],
                              capture_output=True, text=True, preexec_fn=preexec)
        return done.returncode, done.stderr

    def state(folder):
        files = {}
        for path in sorted(folder.glob("*")) if folder.exists() else []:
            files[path.name] = path.read_bytes().decode("latin-1")
        return files

    for step, size in enumerate(sizes):
        out = disk / f"run{step}"
        if mode == "tmpfs":
            filler = disk / "filler"
            filler.unlink(missing_ok=True)
            total = os.statvfs(disk)
            free = total.f_bavail * total.f_frsize
            with filler.open("wb") as handle:  # leave `size` pages free
                handle.write(b"\\0" * max(0, free - size * 4096))
            rc, err = run(out)
            failed = state(out / "corridor")
            filler.unlink()
        else:
            rc, err = run(out, limit=size)
            failed = state(out / "corridor")
        rc2, err2 = run(out)
        print(json.dumps({"step": step, "size": size, "rc": rc, "stderr": err, "files": failed, "rc_again": rc2,
                          "stderr_again": err2, "summary_again": state(out / "corridor").get("summary.json")}),
              flush=True)
''')


def _private_tmpfs() -> bool:
    if shutil.which("unshare") is None:
        return False
    probe = subprocess.run(["unshare", "-rm", "sh", "-c", "mount -t tmpfs -o size=64k tmpfs /mnt 2>/dev/null "
                            "|| mount -t tmpfs -o size=64k tmpfs \"$TMPDIR\""], capture_output=True)
    return probe.returncode == 0


@pytest.mark.skipif(sys.platform != "linux", reason="tmpfs and RLIMIT_FSIZE are Linux's")
def test_a_full_disk_leaves_no_partial_file_and_a_rerun_resumes(tmp_path):
    reference = tmp_path / "reference"
    subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", *COMMAND, "--out", str(reference)], check=True,
                   capture_output=True)
    expected = results_of(reference / "corridor" / "summary.json")
    largest = max(p.stat().st_size for p in (reference / "corridor").iterdir())
    script = tmp_path / "scenario.py"
    script.write_text(SCENARIO)
    disk = tmp_path / "disk"
    disk.mkdir()
    if _private_tmpfs():  # free pages: none, one (settings only), ..., around what the whole run needs
        needed = sum(-(-p.stat().st_size // PAGE) for p in (reference / "corridor").iterdir())
        mode, sizes = "tmpfs", sorted({0, 1, 2, 3, needed - 2, needed - 1, needed, needed + 1})
        launch = ["unshare", "-rm", "sh", "-c", f'mount -t tmpfs -o size=4m tmpfs "{disk}" && exec "$0" "$@"',
                  sys.executable]
    else:
        mode, sizes = "limit", [100, 250, 1024, largest // 2, largest - 1, largest]  # (0 fails at start-up)
        launch = [sys.executable]
    done = subprocess.run([*launch, str(script), str(disk), mode, json.dumps(sizes), json.dumps(COMMAND)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    outcomes = [json.loads(line) for line in done.stdout.splitlines()]
    assert len(outcomes) == len(sizes)
    named = set()
    for outcome in outcomes:
        step, files = outcome["size"], outcome["files"]
        assert outcome["rc_again"] == 0, (step, outcome["stderr_again"])
        assert results_of(outcome["summary_again"]) == expected, step
        kept = {"settings.json", "records.csv", "records.csv.torn", "summary.json", "corridor.png", ".qrrt-lock"}
        assert set(files) <= kept, \
            (step, sorted(files))  # no temporary file left behind
        if outcome["rc"] == 0:
            continue
        lines = outcome["stderr"].strip().splitlines()
        assert outcome["rc"] == 1 and len(lines) == 1 and "Traceback" not in outcome["stderr"], (step, lines)
        assert "No space left" in lines[0] or "too large" in lines[0], (step, lines)
        first = re.search(r"/corridor/([\w.]+): ", lines[0])  # the message names the file first
        assert first is not None, (step, lines)
        file = first.group(1)
        assert "run the same command again" in lines[0] or file == "settings.json", (step, lines)
        named.add(file)
        for name, content in files.items():
            if name.endswith(".json"):
                json.loads(content)  # whole, or absent
            elif name.endswith(".png"):
                assert content.encode("latin-1").endswith(b"IEND\xaeB`\x82"), (step, name)
    every_write = {"settings.json", "records.csv", "corridor.png", "summary.json"}
    assert named == every_write if mode == "tmpfs" else len(named) >= 3, named  # the disk filled at each
