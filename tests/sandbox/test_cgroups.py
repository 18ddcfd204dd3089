"""cgroup v2 limits (issue 14, finding 7) against a directory laid out like a cgroup2 filesystem.

The lab machine binds memory and pids to cgroup v1, so the kernel's v2 enforcement cannot run
here; these tests check what we write, where, and the fallback. The v1 path is exercised for real
by tests/sandbox/test_attacks.py.
"""

from __future__ import annotations

import logging
from pathlib import Path

import pytest

from sandbox import cgroups
from sandbox.cgroups import ROOT_ENV, CgroupsV2, cgroup2_mount, detect, detect_v2, own_v2_path
from sandbox.limits import DEFAULT_LIMITS

# Real samples in the format of a systemd v2 host (Ubuntu 22.04 user session, a service unit).
MOUNTINFO = """\
22 29 0:21 / /proc rw,nosuid,nodev,noexec,relatime shared:12 - proc proc rw
25 29 0:23 / /run rw,nosuid,nodev,noexec,relatime shared:2 - tmpfs tmpfs rw,size=1631572k,mode=755
29 1 8:2 / / rw,relatime shared:1 - ext4 /dev/sda2 rw,errors=remount-ro
35 24 0:30 / {mount} rw,nosuid,nodev,noexec,relatime shared:9 - cgroup2 cgroup2 rw,nsdelegate
"""
PROC_CGROUP = "0::/system.slice/robodojo.service\n"


def fake_cgroup(path: Path, controllers: str, procs: str = "", root: bool = False) -> Path:
    """A directory with the interface files a delegated non-root cgroup v2 directory has."""
    path.mkdir(parents=True, exist_ok=True)
    (path / "cgroup.controllers").write_text(controllers + "\n")
    (path / "cgroup.subtree_control").write_text("")
    (path / "cgroup.procs").write_text(procs)
    if not root:
        (path / "cgroup.type").write_text("domain\n")
    return path


def test_mountinfo_and_proc_cgroup_samples_parse():
    assert cgroup2_mount(MOUNTINFO.format(mount="/sys/fs/cgroup")) == ("/", "/sys/fs/cgroup")
    assert cgroup2_mount(MOUNTINFO.format(mount="/mnt/with\\040space")) == ("/", "/mnt/with space")
    assert cgroup2_mount(MOUNTINFO.splitlines()[0]) is None
    assert own_v2_path(PROC_CGROUP) == "/system.slice/robodojo.service"
    # A hybrid (v1 + empty v2) host, like the lab machine.
    assert own_v2_path("4:memory:/user.slice\n1:name=systemd:/x\n0::/user.slice\n") == "/user.slice"
    assert own_v2_path("4:memory:/user.slice\n") is None


def test_own_delegated_cgroup_moves_server_to_a_leaf_and_limits_each_node(tmp_path, caplog):
    mount = tmp_path / "cgroup"
    fake_cgroup(mount, "cpuset cpu io memory hugetlb pids rdma misc", root=True)
    service = fake_cgroup(
        mount / "system.slice" / "robodojo.service", "cpu memory pids", procs="4242\n"
    )
    (service / "memory.swap.max").write_text("max\n")
    with caplog.at_level(logging.WARNING):
        groups = detect_v2(MOUNTINFO.format(mount=mount), PROC_CGROUP)
    assert isinstance(groups, CgroupsV2) and caplog.records == []
    assert (service / "server" / "cgroup.procs").read_text() == "4242"
    assert (service / "cgroup.subtree_control").read_text() == "+memory +pids +cpu"
    assert cgroups.describe(groups) == f"cgroup v2 under {service} (memory.max, pids.max, cpu.max)"

    node = groups.create(DEFAULT_LIMITS)
    directory = Path(node.directories[0])
    assert directory.parent == service
    assert (directory / "memory.max").read_text() == str(768 * 1024 * 1024)
    assert (directory / "memory.swap.max").read_text() == "0"
    assert (directory / "pids.max").read_text() == "32"
    assert (directory / "cpu.max").read_text() == "100000 100000"
    assert node.procs_files == [str(directory / "cgroup.procs")]

    assert not node.oom_killed()
    (directory / "memory.events").write_text("low 0\nhigh 0\nmax 3\noom 1\noom_kill 1\n")
    assert node.oom_killed()

    # The kernel drops a group's interface files with it; a plain directory needs them gone.
    for file in directory.iterdir():
        file.unlink()
    node.remove()
    assert not directory.exists()


def test_configured_root_is_used_and_the_hierarchy_root_keeps_its_processes(tmp_path):
    root = fake_cgroup(tmp_path / "cgroup", "memory pids", procs="1\n", root=True)
    groups = detect({ROOT_ENV: str(root)})
    assert isinstance(groups, CgroupsV2)
    assert not (root / "server").exists()  # the hierarchy root is exempt from the leaf rule
    assert (root / "cgroup.subtree_control").read_text() == "+memory +pids"
    node = groups.create(DEFAULT_LIMITS)
    directory = Path(node.directories[0])
    assert not (directory / "cpu.max").exists() and not (directory / "memory.swap.max").exists()
    assert groups.describe() == f"cgroup v2 under {root} (memory.max, pids.max)"


@pytest.mark.parametrize("controllers", ["cpu pids", "cpu memory", ""])
def test_missing_controller_falls_back_to_rlimits_with_one_warning(
    tmp_path, caplog, monkeypatch, controllers
):
    monkeypatch.setattr(cgroups, "in_container", lambda: False)
    root = fake_cgroup(tmp_path / "robodojo", controllers, procs="4242\n")
    with caplog.at_level(logging.WARNING, logger="sandbox.cgroups"):
        assert detect({ROOT_ENV: str(root)}) is None
    [record] = caplog.records
    message = record.getMessage()
    missing = [c for c in ("memory", "pids") if c not in controllers.split()]
    assert f"does not offer the {' and '.join(missing)} controller" in message
    assert "Delegate=yes" in message and ROOT_ENV in message
    assert (root / "cgroup.subtree_control").read_text() == ""  # nothing enabled, nobody moved
    assert not (root / "server").exists()
    assert cgroups.describe(None) == "rlimits only (no usable cgroup)"


def test_no_cgroup2_mount_falls_back(caplog):
    with caplog.at_level(logging.WARNING, logger="sandbox.cgroups"):
        assert detect_v2(MOUNTINFO.splitlines()[0], PROC_CGROUP) is None
    assert "no cgroup2 filesystem" in caplog.records[0].getMessage()


def test_in_a_container_the_warning_points_at_the_container_docs(tmp_path, caplog, monkeypatch):
    # systemd's Delegate=yes means nothing inside a container: the advice names what to give it.
    monkeypatch.setattr(cgroups, "in_container", lambda: True)
    root = fake_cgroup(tmp_path / "robodojo", "cpu", procs="")
    with caplog.at_level(logging.WARNING, logger="sandbox.cgroups"):
        assert detect({ROOT_ENV: str(root)}) is None
    [record] = caplog.records
    message = record.getMessage()
    assert "rlimits only" in message and "docker/README.md" in message and ROOT_ENV in message
    assert "Delegate=yes" not in message
