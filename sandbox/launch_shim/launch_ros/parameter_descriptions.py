"""Stand-in for `launch_ros.parameter_descriptions`."""

from sandbox.launch2.missing import missing
from sandbox.launch2.parameters import Parameter, ParameterFile, ParameterValue

__all__ = ["Parameter", "ParameterFile", "ParameterValue"]
__getattr__ = missing("launch_ros.parameter_descriptions")
