"""The hardware tests reuse the run tests' real sandbox launcher."""

from tests.runs.conftest import launcher  # noqa: F401  (a pytest fixture, used by name)
