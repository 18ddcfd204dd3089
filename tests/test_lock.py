"""The locks (requirements/*.txt, made by scripts/lock) against pyproject.toml and the running
environment: every requirement is pinned by a version its range admits, with hashes, for each
interpreter we support; the runtime lock is the test lock's versions; and the environment
scripts/venv built (it leaves a stamp in it) holds exactly the lock, no package more or less.
"""

from __future__ import annotations

import re
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import pytest
from packaging.markers import default_environment
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parent.parent
LOCKS = ROOT / "requirements"
# The interpreters the locks are resolved for (scripts/lock): the oldest each lock admits and the
# newer ones a user meets (Debian trixie's is 3.13).
SUPPORTED_PYTHONS = ("3.11.5", "3.12.0", "3.13.0")
STAMP = "robodojo-lock.stamp"  # scripts/venv writes it into an environment built from a lock


class Pin:
    def __init__(self, name: str, version: str, marker: str | None, hashes: list[str]):
        self.name, self.version, self.hashes = name, version, hashes
        self.marker = Requirement(f"{name}=={version}; {marker}").marker if marker else None

    def applies(self, environment: dict[str, str]) -> bool:
        return self.marker is None or self.marker.evaluate(environment)


def read_lock(name: str) -> list[Pin]:
    """The pins of a lock file: `name==version ; marker \\` lines, each with its --hash lines."""
    pins: list[Pin] = []
    for line in (LOCKS / name).read_text(encoding="utf-8").splitlines():
        pinned = re.match(r"([A-Za-z0-9._-]+)==([^\s;\\]+)\s*(?:;\s*([^\\]+?))?\s*\\?$", line)
        if pinned:
            pins.append(Pin(canonicalize_name(pinned[1]), pinned[2], pinned[3], []))
        elif line.strip().startswith("--hash=") and pins:
            pins[-1].hashes.append(line.strip().removeprefix("--hash=").rstrip(" \\"))
    return pins


def environment_for(python: str) -> dict[str, str]:
    environment = default_environment()
    environment.update(
        python_full_version=python,
        python_version=".".join(python.split(".")[:2]),
        sys_platform="linux",
        platform_system="Linux",
        implementation_name="cpython",
        platform_python_implementation="CPython",
        os_name="posix",
    )
    return environment


def resolved(pins: list[Pin], environment: dict[str, str]) -> dict[str, str]:
    chosen: dict[str, str] = {}
    for pin in pins:
        if pin.applies(environment):
            assert pin.name not in chosen, f"{pin.name} is pinned twice for {environment}"
            chosen[pin.name] = pin.version
    return chosen


def project_requirements() -> tuple[list[Requirement], list[Requirement]]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    tools = [
        Requirement(line)
        for line in (LOCKS / "tools.in").read_text(encoding="utf-8").splitlines()
        if line.strip() and not line.startswith("#")
    ]
    build = [Requirement(text) for text in project["build-system"]["requires"]]
    runtime = [Requirement(text) for text in project["project"]["dependencies"]] + tools + build
    test = runtime + [Requirement(t) for t in project["project"]["optional-dependencies"]["test"]]
    return runtime, test


def check_lock_admits(requirements: list[Requirement], lock: str, python: str) -> None:
    environment = environment_for(python)
    chosen = resolved(read_lock(lock), environment)
    for requirement in requirements:
        if requirement.marker and not requirement.marker.evaluate(environment):
            continue
        name = canonicalize_name(requirement.name)
        assert name in chosen, f"{lock} pins no {name} for Python {python}: run ./scripts/lock"
        assert requirement.specifier.contains(chosen[name], prereleases=True), (
            f"{lock} pins {name}=={chosen[name]}, outside pyproject.toml's {requirement}: "
            "run ./scripts/lock"
        )


@pytest.mark.parametrize("python", SUPPORTED_PYTHONS)
def test_each_lock_pins_every_requirement_within_its_range(python):
    runtime, test = project_requirements()
    check_lock_admits(runtime, "runtime.txt", python)
    check_lock_admits(test, "test.txt", python)


def test_every_pin_carries_a_sha256_hash():
    for lock in ("runtime.txt", "test.txt"):
        pins = read_lock(lock)
        assert len(pins) > 50, f"{lock} holds {len(pins)} pins: not a lock of the whole tree"
        for pin in pins:
            assert pin.hashes, f"{lock}: {pin.name} has no hash (pip's --require-hashes refuses)"
            assert all(h.startswith("sha256:") and len(h) == 71 for h in pin.hashes), pin.name


@pytest.mark.parametrize("python", SUPPORTED_PYTHONS)
def test_the_runtime_lock_is_the_test_locks_versions(python):
    environment = environment_for(python)
    runtime = resolved(read_lock("runtime.txt"), environment)
    test = resolved(read_lock("test.txt"), environment)
    differ = {name: (version, test.get(name)) for name, version in runtime.items()}
    differ = {name: pair for name, pair in differ.items() if pair[0] != pair[1]}
    assert not differ, f"runtime.txt and test.txt disagree (runtime, test): {differ}"


def test_a_lock_read_back_finds_what_was_written(tmp_path, monkeypatch):
    """The reader above must not pass a lock by seeing nothing in it."""
    (tmp_path / "x.txt").write_text(
        "numpy==2.4.6 ; python_full_version < '3.12' \\\n"
        "    --hash=sha256:" + "a" * 64 + "\n"
        "numpy==2.5.5 ; python_full_version >= '3.12' \\\n"
        "    --hash=sha256:" + "b" * 64 + "\n"
        "    # via robodojo\n",
        encoding="utf-8",
    )
    monkeypatch.setattr(sys.modules[__name__], "LOCKS", tmp_path)
    pins = read_lock("x.txt")
    assert [(p.name, p.version, len(p.hashes)) for p in pins] == [
        ("numpy", "2.4.6", 1),
        ("numpy", "2.5.5", 1),
    ]
    assert resolved(pins, environment_for("3.11.7")) == {"numpy": "2.4.6"}
    assert resolved(pins, environment_for("3.12.1")) == {"numpy": "2.5.5"}
    with pytest.raises(AssertionError, match=re.escape("outside pyproject.toml's numpy>=3")):
        check_lock_admits([Requirement("numpy>=3")], "x.txt", "3.12.1")


def test_the_locked_environment_holds_exactly_the_lock():
    """What `pip list` shows where scripts/test ran is the lock for this interpreter, no more."""
    stamp = Path(sys.prefix) / STAMP
    if not stamp.exists():
        pytest.skip(
            f"not run from an environment scripts/venv built ({sys.prefix} has no {STAMP}): "
            "./scripts/test makes one"
        )
    python = ".".join(str(part) for part in sys.version_info[:3])
    locked = resolved(read_lock("test.txt"), environment_for(python))
    installed = {
        canonicalize_name(dist.metadata["Name"]): dist.version for dist in metadata.distributions()
    }
    installed.pop("robodojo")  # the checkout itself, editable
    assert installed == locked
