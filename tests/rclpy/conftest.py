"""The real launcher (bubblewrap + seccomp) for the tests that run rclpy nodes sandboxed."""

from tests.sandbox.conftest import launcher  # noqa: F401
