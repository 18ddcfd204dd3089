"""The editor's help: diagnostics, completion, hover and formatting of a student's text, which
is read, never run. `service.EditorService` is the door; ruff runs per request (ruff_tool), our
API checks (api_checks) and jedi (complete) in worker processes (pool, worker)."""
