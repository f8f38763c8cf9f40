"""The folders of the process's control groups for one controller (Linux cgroups v1 and v2), from
its own group up to the mount's root: where the memory limits (``available_memory``) and the CPU
quota (``free_cores``) of a container are read.

The groups are found from ``/proc/self/cgroup`` (``hierarchy:controllers:path`` lines; in a
container with its own cgroup namespace, the container's group is the mount's root). The v2
hierarchy (empty controller list) is mounted at the root of ``/sys/fs/cgroup`` or at its
``unified`` folder beside v1's controllers; a v1 controller at ``/sys/fs/cgroup/<controller>``
(a joint mount such as ``cpu,cpuacct`` has a link of each controller's name).
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["group_folders"]


def group_folders(controller: str, proc_cgroup: str, cgroup_root: str) -> list[tuple[Path, int]]:
    """(folder, cgroup version) of every group of the process that ``controller`` governs, each
    from the process's own group up to its mount's root; empty where ``proc_cgroup`` cannot be
    read (not Linux).

    Args:
        controller: The v1 controller's name (``"memory"``, ``"cpu"``); the v2 hierarchy is always
            included.
        proc_cgroup: The process's group list (``/proc/self/cgroup``).
        cgroup_root: Where the control-group file systems are mounted (``/sys/fs/cgroup``).

    Returns:
        The folders, each with 2 (the unified hierarchy) or 1 (a v1 controller's).
    """
    try:
        with open(proc_cgroup, encoding="utf-8", errors="surrogateescape") as handle:  # any group name
            lines = handle.read().splitlines()
    except OSError:
        return []
    groups: list[tuple[Path, int]] = []
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        controllers, path = parts[1], parts[2].lstrip("/")
        if controllers == "":  # the v2 hierarchy
            mounts = [(Path(cgroup_root), 2), (Path(cgroup_root) / "unified", 2)]
        elif controller in controllers.split(","):
            mounts = [(Path(cgroup_root) / controller, 1)]  # (a joint mount has a link of each name)
        else:
            continue
        for root, version in mounts:
            folder = root / path
            while True:
                groups.append((folder, version))
                if folder == root or root not in folder.parents:
                    break
                folder = folder.parent
    return groups
