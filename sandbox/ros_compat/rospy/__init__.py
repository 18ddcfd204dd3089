"""A rospy-compatible API for RoboDojo nodes: ROS 1 teaching scripts run unchanged.

Behaviour follows rospy where a student can observe it: publishing queues a message that leaves
at the next sleep; callbacks run inside sleep()/spin(); Rate keeps a fixed schedule; shutdown
makes sleeps raise ROSInterruptException. What differs is said with a sentence when used.
The state lives in sandbox.runtime; these modules only shape the API.
"""

from sandbox.msgs import Duration, Time
from sandbox.runtime import (
    ROSException,
    ROSInitException,
    ROSInterruptException,
    ROSSerializationException,
)
from sandbox.timers import TimerEvent

from . import exceptions
from .core import (
    DEBUG,
    ERROR,
    FATAL,
    INFO,
    WARN,
    delete_param,
    get_caller_id,
    get_name,
    get_namespace,
    get_node_uri,
    get_param,
    get_param_cached,
    get_param_names,
    has_param,
    init_node,
    is_shutdown,
    is_shutdown_requested,
    myargv,
    on_shutdown,
    resolve_name,
    search_param,
    set_param,
    signal_shutdown,
    spin,
)
from .log import (
    logdebug,
    logdebug_once,
    logdebug_throttle,
    logerr,
    logerr_once,
    logerr_throttle,
    logerror,
    logfatal,
    logfatal_once,
    logfatal_throttle,
    loginfo,
    loginfo_once,
    loginfo_throttle,
    logout,
    logwarn,
    logwarn_once,
    logwarn_throttle,
)
from .msg import AnyMsg
from .services import Service, ServiceException, ServiceProxy, wait_for_service
from .timing import Rate, Timer, get_rostime, get_time, sleep
from .topics import (
    Publisher,
    SubscribeListener,
    Subscriber,
    get_published_topics,
    wait_for_message,
)

__all__ = [
    "DEBUG",
    "ERROR",
    "FATAL",
    "INFO",
    "WARN",
    "AnyMsg",
    "Duration",
    "Publisher",
    "ROSException",
    "ROSInitException",
    "ROSInterruptException",
    "ROSSerializationException",
    "Rate",
    "Service",
    "ServiceException",
    "ServiceProxy",
    "SubscribeListener",
    "Subscriber",
    "Time",
    "Timer",
    "TimerEvent",
    "delete_param",
    "exceptions",
    "get_caller_id",
    "get_name",
    "get_namespace",
    "get_node_uri",
    "get_param",
    "get_param_cached",
    "get_param_names",
    "get_published_topics",
    "get_rostime",
    "get_time",
    "has_param",
    "init_node",
    "is_shutdown",
    "is_shutdown_requested",
    "logdebug",
    "logdebug_once",
    "logdebug_throttle",
    "logerr",
    "logerr_once",
    "logerr_throttle",
    "logerror",
    "logfatal",
    "logfatal_once",
    "logfatal_throttle",
    "loginfo",
    "loginfo_once",
    "loginfo_throttle",
    "logout",
    "logwarn",
    "logwarn_once",
    "logwarn_throttle",
    "myargv",
    "on_shutdown",
    "resolve_name",
    "search_param",
    "set_param",
    "signal_shutdown",
    "sleep",
    "spin",
    "wait_for_message",
    "wait_for_service",
]

# Parts of rospy that talk to a ROS master or to other machines; each has a sentence that says
# why it is absent and what to use instead.
_NOT_PROVIDED = {
    "get_master": "there is no ROS master in a RoboDojo run; rospy.get_published_topics() "
    "lists the run's topics",
    "Header": "use std_msgs.msg.Header",
    "names": "use rospy.resolve_name() and rospy.get_name()",
    "impl": "rospy's transport internals are not part of RoboDojo's rospy",
    "wallsleep": "use rospy.sleep(): a run's time is the robot's time",
    "get_rostime_wall": "use rospy.get_time()",
}


def __getattr__(name: str) -> object:
    import difflib

    reason = _NOT_PROVIDED.get(name)
    if reason is not None:
        raise AttributeError(f"rospy.{name} is not available in RoboDojo nodes: {reason}")
    if name.startswith("__"):
        raise AttributeError(name)
    close = difflib.get_close_matches(name, __all__, n=2)
    hint = f"did you mean {' or '.join('rospy.' + c for c in close)}? " if close else ""
    raise AttributeError(
        f"rospy has no '{name}' in RoboDojo: {hint}docs/controllers.md lists what RoboDojo's "
        "rospy provides"
    )
