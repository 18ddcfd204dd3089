"""ROS 2 Python launch files, evaluated inside the sandbox (never in the server's process).

A `.launch.py` file is student code: `generate_launch_description()` can run anything. So the
server starts a one-shot sandboxed job (`Api.LAUNCH`, sandbox/launch2/job.py) that execs the
file with stand-ins for `launch`, `launch_ros` and `ament_index_python` (sandbox/launch_shim/,
on sys.path only inside that job), visits the description it returns as ros2 launch would, and
answers with a `Plan` (plan.py): each node's workspace file, name, namespace, parameters,
remappings and arguments. The server (server/runs/launch_py.py) turns the plan into NodeSpecs.

Behaviour follows ros2/launch and ros2/launch_ros (launch_service.py's depth-first visit,
actions/*.py, substitutions/*.py, launch_ros/actions/node.py's `_perform_substitutions`), and
rcl's YAML parameter files (rcl_yaml_param_parser; rclpy node.cpp's wildcard matching).
Modules: errors.py (LaunchError with the launch file's line), context.py (launch
configurations, their scopes, what is being read), substitutions.py, conditions.py,
actions.py (launch's actions), ros_actions.py (launch_ros's), parameters.py (parameter dicts
and files), packages.py (the ament index over the workspace, executables), evaluate.py (load
and visit), plan.py (the answer), job.py (the node host's entry).
"""
