"""Classes are built on first use: importing costs no class, every path gives the same class.

The start-up checks run in a fresh interpreter, since this process has built most types already.
"""

from __future__ import annotations

import pickle
import subprocess
import sys
import textwrap

import pytest

from sandbox.msgs import MESSAGE_TYPES, geometry_msgs, get_message_class, sensor_msgs, std_msgs
from sandbox.msgs._catalog import names, packages
from sandbox.msgs._lazy import MissingTypeError


def run_fresh(code: str) -> str:
    """stdout of ``code`` run by a new interpreter (fails the test on any error)."""
    result = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_importing_the_package_builds_no_class() -> None:
    out = run_fresh(
        """
        import sandbox.msgs as msgs
        from sandbox.msgs import _core
        print(len(_core._REGISTRY), len(msgs.MESSAGE_TYPES), len(dir(msgs.nav_msgs)))
        """
    )
    built, listed, nav_names = map(int, out.split())
    assert built == 0
    assert listed >= 140 and nav_names > 12  # listing and dir() do not build either


def test_first_use_builds_the_type_and_its_nested_types_only() -> None:
    out = run_fresh(
        """
        from sandbox.msgs.geometry_msgs import Twist
        from sandbox.msgs import _core
        print(*sorted(_core._REGISTRY))
        """
    )
    assert out.split() == ["geometry_msgs/Twist", "geometry_msgs/Vector3"]


def test_concurrent_first_use_builds_one_class() -> None:
    # Callback threads may reach a type for the first time together; all must get one class.
    out = run_fresh(
        """
        import sys, threading
        sys.setswitchinterval(1e-6)  # switch threads as often as possible
        from sandbox.msgs import get_message_class
        barrier = threading.Barrier(8)
        found = []
        def build():
            barrier.wait()
            found.append(get_message_class("visualization_msgs/InteractiveMarkerUpdate"))
        threads = [threading.Thread(target=build) for _ in range(8)]
        for thread in threads: thread.start()
        for thread in threads: thread.join()
        print(len(found), len({id(cls) for cls in found}))
        """
    )
    assert out.split() == ["8", "1"]


def test_every_path_gives_the_same_class() -> None:
    assert (
        std_msgs.Header is get_message_class("std_msgs/Header") is MESSAGE_TYPES["std_msgs/Header"]
    )
    assert sensor_msgs.Imu._field_specs[0].message_class is std_msgs.Header
    from sandbox.msgs.geometry_msgs import Twist

    assert Twist is geometry_msgs.Twist


def test_classes_pickle_by_their_module_path() -> None:
    marker = get_message_class("visualization_msgs/Marker")(ns="demo", id=3)
    assert marker.__class__.__module__ == "sandbox.msgs.visualization_msgs"
    assert pickle.loads(pickle.dumps(marker)) == marker


@pytest.mark.parametrize("package", packages())
def test_dir_and_all_list_every_type_of_the_package(package: str) -> None:
    module = __import__(f"sandbox.msgs.{package}", fromlist=["_"])
    everything = set(names(package, "msg")) | set(names(package, "srv"))
    assert set(module.__all__) == everything
    assert everything <= set(dir(module))
    for name in module.__all__:
        assert getattr(module, name)._type == f"{package}/{name}"


def test_a_missing_attribute_is_an_attribute_error_with_a_sentence() -> None:
    with pytest.raises(MissingTypeError) as caught:
        std_msgs.Int33  # noqa: B018
    assert isinstance(caught.value, AttributeError)
    assert str(caught.value).startswith(
        "sandbox.msgs.std_msgs has no type 'Int33'. Did you mean Int32, UInt32 or Int8? It holds: "
        "Bool, Byte, ByteMultiArray,"
    )
    assert not hasattr(std_msgs, "Int33")
    assert getattr(std_msgs, "Int33", None) is None


def test_a_missing_name_in_from_import_is_an_import_error_with_the_sentence() -> None:
    # Python turns an AttributeError from a module's __getattr__ into its own "cannot import
    # name"; the sentence must survive.
    with pytest.raises(ImportError) as caught:
        from sandbox.msgs.std_msgs import Twist  # noqa: F401
    assert not isinstance(caught.value, AttributeError)
    assert str(caught.value).startswith(
        "sandbox.msgs.std_msgs has no type 'Twist'. Did you mean geometry_msgs.msg.Twist?"
    )


def test_private_probes_get_a_plain_attribute_error() -> None:
    # copy, pickle and inspect look for dunder names; they must not get a list of message types.
    with pytest.raises(AttributeError, match=r"^module 'sandbox\.msgs\.std_msgs' has no attribute"):
        std_msgs.__wrapped__  # noqa: B018
