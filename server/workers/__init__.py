"""Where runs execute: worker processes, on this machine or on others (issue 16).

The web process (`robodojo serve`) accepts a run, stores its record and hands a `RunJob`
(wire.py) to a `RunExecutor` (seams.py); it never runs one itself. A worker holds running runs
in a `RunHost`, stores their state changes and results in the shared database, judges them, and
sends their live traffic (telemetry samples latest-wins per topic, logs, state changes, check
results, a status snapshot a few times a second) through a `LiveOutlet`. Commands (stop, pause,
button, estop, ...) go the other way as typed commands and get an answer.

Three executors stand behind the same seam:

* in-process (`RunHost` in the web process's threads): `robodojo run`, tests, and the runs of a
  robot whose connection the web process itself holds;
* local processes (the embedded default, no Redis): one worker process per core, started and
  watched by the web process, jobs and live traffic over pipes;
* the cluster (`--redis-url`): runs are Dramatiq jobs over Redis, taken by `robodojo worker`
  processes on any machine; live traffic over Redis pub/sub, recordings on a shared data volume.
"""
