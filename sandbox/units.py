"""Unit constants shared by the sandbox and the server (which imports the sandbox, never the
other way round). Time inside a run is kept in integer nanoseconds so schedules never drift with
float rounding; this is the one place the factor is written."""

NS_PER_S = 1_000_000_000  # [ns/s]
