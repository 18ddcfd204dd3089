"""The editor's help: diagnostics, completion, hover and formatting of a student's text, which
is read, never run. `service.EditorService` is the door; `gate` decides who is analysed when;
jedi (complete), our API checks (api_checks) and ruff (ruff_tool) read the text inside the
editor's sandbox, in a process per request (sandbox_host, host, request; limits)."""
