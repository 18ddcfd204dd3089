"""`std_srvs.srv`: the service classes of sandbox.msgs.std_srvs, built on first use."""

from sandbox.msgs._lazy import install

install(globals(), "std_srvs", ("srv",))
