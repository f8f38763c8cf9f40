"""The free cores: the busy time other work takes, measured from the kernel's CPU time counters
between two readings (``BusyMeter``), the one-minute load before the first interval ends."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from qrrt_circuits._support import free_cores as fc
from qrrt_circuits._support.free_cores import BusyMeter, CpuTimes


@pytest.fixture(autouse=True)
def _no_cpu_quota(tmp_path, monkeypatch):
    """The machine's own control groups are not read unless a test makes its own."""
    monkeypatch.setattr(fc, "PROC_CGROUP", str(tmp_path / "no-cgroup-file"))


def readings(*values: CpuTimes | None):
    """A reader handing back ``values`` in turn."""
    queue = list(values)
    return lambda: queue.pop(0)


def test_the_meter_subtracts_this_process_time_over_the_interval():
    """Others' cores = (busy ticks - own ticks) / ticks per CPU; nothing until a first interval."""
    meter = BusyMeter(readings(CpuTimes(1000, 4000, 50, 4, 7), CpuTimes(1250, 4400, 150, 4, 7),
                               CpuTimes(1250, 4800, 150, 4, 7)), min_interval_ticks=25)
    assert meter.others() is None  # the first reading starts the count
    assert meter.others() == pytest.approx((250 - 100) / 100)  # 100 ticks a CPU, 150 of them others'
    assert meter.others() == 0.0  # an idle interval


def test_a_short_interval_keeps_the_last_measurement():
    """A reading sooner than the minimum interval after the last measured one keeps its value and
    does not move the interval's start."""
    meter = BusyMeter(readings(CpuTimes(0, 0, 0, 2, 7), CpuTimes(40, 20, 0, 2, 7), CpuTimes(100, 100, 0, 2, 7),
                               CpuTimes(110, 120, 0, 2, 7), CpuTimes(110, 160, 0, 2, 7)), min_interval_ticks=25)
    assert meter.others() is None
    assert meter.others() is None  # 10 ticks a CPU: too short, nothing measured yet
    assert meter.others() == pytest.approx(100 / 50)  # from the first reading: 50 ticks a CPU
    assert meter.others() == pytest.approx(2.0)  # 10 ticks a CPU since: kept
    assert meter.others() == pytest.approx(10 / 30)  # 30 ticks a CPU since the measured reading


def test_the_meter_restarts_in_a_forked_child_and_never_goes_negative():
    """A reading of another process (a forked child's own count starts at 0) or of another CPU set
    restarts the count; own ticks beyond the busy ones (the kernel's sampling) give 0, not less."""
    meter = BusyMeter(readings(CpuTimes(0, 0, 500, 2, 7), CpuTimes(100, 100, 3, 2, 8), CpuTimes(100, 100, 3, 1, 8),
                               CpuTimes(110, 200, 40, 1, 8)), min_interval_ticks=25)
    assert meter.others() is None
    assert meter.others() is None  # pid 8: a new count, not 500 own ticks fewer
    assert meter.others() is None  # one CPU now: a new count
    assert meter.others() == 0.0  # 10 busy, 37 own


def test_without_counters_the_meter_measures_nothing():
    meter = BusyMeter(lambda: None, min_interval_ticks=25)
    assert meter.others() is None and meter.others() is None


@pytest.mark.parametrize(("others", "usable", "expected"), [
    (0.0, 8, 8), (0.49, 8, 8), (0.51, 8, 7), (2.5, 8, 6), (2.6, 8, 5), (6.2, 8, 2), (6.6, 8, 1), (39.0, 8, 1),
    (0.0, 1, 1), (1.0, 2, 1), (0.3, 2, 2)])
def test_free_cores_rounds_the_measured_busy_cores(monkeypatch, others, usable, expected):
    """The usable cores less others' busy cores, to the nearest core, at least 1 (the load average
    is not read once a measurement exists)."""
    monkeypatch.setattr(fc, "_METER", BusyMeter(readings(CpuTimes(0, 0, 0, 1, 7), CpuTimes(round(100 * others),
                                                                                              100, 0, 1, 7)),
                                                min_interval_ticks=25))
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(usable)))
    monkeypatch.setattr(os, "getloadavg", lambda: (99.0, 99.0, 99.0))
    assert fc.free_cores() == 1 or usable == 1  # first reading: the load (99) stands in
    assert fc.free_cores() == expected


@pytest.mark.skipif(not os.path.exists("/proc/stat"), reason="the kernel's CPU time counters are Linux's")
def test_the_real_counters_are_read():
    """On Linux every usable CPU has a line and the counts only grow."""
    first = fc.read_cpu_times()
    sum(range(200_000))  # (some CPU time of this process)
    second = fc.read_cpu_times()
    assert first is not None and second is not None
    assert first.cpus == second.cpus == fc.usable_cores() and first.pid == second.pid == os.getpid()
    assert 0 <= first.busy <= first.total and first.busy <= second.busy and first.total <= second.total
    assert first.own <= second.own
    assert fc.read_cpu_times(cpus=[10**6]) is None  # no such CPU: no reading


@pytest.mark.skipif(not os.path.exists("/proc/stat") or fc.usable_cores() < 2,
                    reason="needs the kernel's counters and two usable cores")
def test_a_busy_process_beside_this_one_is_measured():
    """A process spinning on one core for the whole interval while this one sleeps keeps most of a
    core busy (its interpreter's start-up is before the interval)."""
    meter = BusyMeter(fc.read_cpu_times, min_interval_ticks=1)
    spin = "import time\nend = time.time() + 1.2\nwhile time.time() < end: pass"
    spinner = subprocess.Popen([sys.executable, "-c", spin])
    try:
        time.sleep(0.2)  # (the child's interpreter starts)
        assert meter.others() is None
        time.sleep(0.6)
        others = meter.others()
    finally:
        spinner.wait(timeout=30)
    assert others is not None and others >= 0.7  # so at least one core counts as busy


def _cpu_groups(tmp_path, monkeypatch, version: int, own: tuple[str, ...], parent: tuple[str, ...]) -> None:
    """Fake CPU control groups of ``version`` for a process in group ``/box`` (parent: the mount's
    root): ``own`` and ``parent`` are the files' contents (v2: ``cpu.max``; v1: quota, period)."""
    root = tmp_path / "cgroup"
    mount = root if version == 2 else root / "cpu"
    names = ("cpu.max",) if version == 2 else ("cpu.cfs_quota_us", "cpu.cfs_period_us")
    for folder, contents in ((mount / "box", own), (mount, parent)):
        folder.mkdir(parents=True, exist_ok=True)
        for name, text in zip(names, contents, strict=True):
            (folder / name).write_text(text + "\n")
    proc = tmp_path / "cgroup.txt"
    proc.write_text("0::/box\n" if version == 2 else "4:memory:/box\n3:cpu,cpuacct:/box\n0::/\n")
    monkeypatch.setattr(fc, "CGROUP_ROOT", str(root))
    monkeypatch.setattr(fc, "PROC_CGROUP", str(proc))


@pytest.mark.parametrize(("version", "own", "parent", "quota"), [
    (2, ("150000 100000",), ("max 100000",), 1.5),
    (2, ("max 100000",), ("300000 100000",), 3.0),  # a parent's quota bounds its children
    (2, ("max 100000",), ("max 100000",), None),
    (2, ("garbage",), ("max",), None),
    (1, ("150000", "100000"), ("-1", "100000"), 1.5),
    (1, ("-1", "100000"), ("-1", "100000"), None),
])
def test_the_cpu_quota_is_read_from_the_control_groups(tmp_path, monkeypatch, version, own, parent, quota):
    _cpu_groups(tmp_path, monkeypatch, version, own, parent)
    assert fc.cpu_quota_cores() == quota


def test_a_cpu_quota_caps_the_usable_and_the_free_cores(tmp_path, monkeypatch):
    """8 CPUs under a quota of 1.5 cores: 2 usable (rounded up); other work's busy cores are counted
    on the 8 CPUs, so 3 busy ones still leave the 2 the quota allows, 7 busy ones leave 1."""
    _cpu_groups(tmp_path, monkeypatch, 2, ("150000 100000",), ("max 100000",))
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(8)))
    assert fc.usable_cores() == 2
    for others, expected in ((0.0, 2), (3.0, 2), (6.4, 2), (6.6, 1), (7.0, 1)):
        monkeypatch.setattr(fc, "_METER", BusyMeter(readings(CpuTimes(0, 0, 0, 8, 7), CpuTimes(
            round(100 * others), 800, 0, 8, 7)), min_interval_ticks=25))
        fc.free_cores()  # (the first reading)
        assert fc.free_cores() == expected, others
    _cpu_groups(tmp_path, monkeypatch, 2, ("max 100000",), ("max 100000",))
    assert fc.usable_cores() == 8


def test_without_control_groups_there_is_no_quota(tmp_path, monkeypatch):
    monkeypatch.setattr(fc, "PROC_CGROUP", str(tmp_path / "absent"))
    assert fc.cpu_quota_cores() is None
    assert fc.usable_cores() == len(fc.usable_cpus())


@pytest.mark.skipif(not os.path.exists("/proc/self/comm"), reason="the process name is Linux's /proc/self/comm")
def test_a_process_name_with_spaces_and_other_bytes_is_read_past():
    """``/proc/self/stat`` holds the process name between parentheses as the kernel has it (any
    bytes, spaces and ')' included): the counters after it are still read."""
    with open("/proc/self/comm", "rb") as handle:
        before = handle.read().rstrip(b"\n")
    try:
        with open("/proc/self/comm", "wb") as handle:
            handle.write("q) r\u00e9t x".encode())
        reading = fc.read_cpu_times()
    finally:
        with open("/proc/self/comm", "wb") as handle:
            handle.write(before)
    assert reading is not None and reading.own >= 0 and reading.cpus == len(fc.usable_cpus())
