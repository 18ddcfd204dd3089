"""rclpy.qos: QoS profiles, their policies, the presets and their compatibility.

Values and presets as rmw/qos_profiles.h and rclpy/qos.py. What a policy changes on a RoboDojo
node (the rest are accepted and kept, as the run has no network to lose messages on):

- depth (KEEP_LAST): a subscription holds at most this many unread messages; older ones are
  dropped, so a callback sees at most `depth` of a burst that arrived while it was not spun.
- reliability: a RELIABLE subscription does not receive from a BEST_EFFORT publisher; both
  sides log rclpy's incompatible-QoS warning, as rmw reports it.
- durability: a TRANSIENT_LOCAL publisher's last message reaches TRANSIENT_LOCAL subscribers
  that come later (a latched topic); a TRANSIENT_LOCAL subscription does not receive from a
  VOLATILE publisher (incompatible, with the warning).
"""

from __future__ import annotations

import warnings
from enum import Enum, IntEnum
from typing import Any

from .duration import Duration


class QoSPolicyKind(IntEnum):
    INVALID = 1 << 0
    DURABILITY = 1 << 1
    DEADLINE = 1 << 2
    LIVELINESS = 1 << 3
    RELIABILITY = 1 << 4
    HISTORY = 1 << 5
    LIFESPAN = 1 << 6
    DEPTH = 1 << 7
    LIVELINESS_LEASE_DURATION = 1 << 8
    AVOID_ROS_NAMESPACE_CONVENTIONS = 1 << 9


def qos_policy_name_from_kind(policy_kind: QoSPolicyKind | int) -> str:
    return QoSPolicyKind(policy_kind).name


class InvalidQoSProfileException(Exception):
    def __init__(self, message: str) -> None:
        super().__init__(f"Invalid QoSProfile: {message}")


class QoSPolicyEnum(IntEnum):
    @classmethod
    def short_keys(cls) -> list[str]:
        return [key.lower() for key in cls.__members__ if not key.startswith("RMW")]

    @classmethod
    def get_from_short_key(cls, name: str) -> int:
        return cls[name.upper()].value

    @property
    def short_key(self) -> str:
        return self.name.lower()


class HistoryPolicy(QoSPolicyEnum):
    SYSTEM_DEFAULT = 0
    KEEP_LAST = 1
    KEEP_ALL = 2
    UNKNOWN = 3


class ReliabilityPolicy(QoSPolicyEnum):
    SYSTEM_DEFAULT = 0
    RELIABLE = 1
    BEST_EFFORT = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


class DurabilityPolicy(QoSPolicyEnum):
    SYSTEM_DEFAULT = 0
    TRANSIENT_LOCAL = 1
    VOLATILE = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


class LivelinessPolicy(QoSPolicyEnum):
    SYSTEM_DEFAULT = 0
    AUTOMATIC = 1
    MANUAL_BY_TOPIC = 3
    UNKNOWN = 4
    BEST_AVAILABLE = 5


QoSHistoryPolicy = HistoryPolicy
QoSReliabilityPolicy = ReliabilityPolicy
QoSDurabilityPolicy = DurabilityPolicy
QoSLivelinessPolicy = LivelinessPolicy

DEPTH_SYSTEM_DEFAULT = 0
# [messages] what a KEEP_ALL subscription holds at most: DDS bounds KEEP_ALL by its resource
# limits too, and a node that never spins must not grow without bound
KEEP_ALL_LIMIT = 1000
_DEFAULTS: dict[str, Any] = {  # rmw's qos_profile_default
    "depth": 10,
    "reliability": ReliabilityPolicy.RELIABLE,
    "durability": DurabilityPolicy.VOLATILE,
    "lifespan": Duration(),
    "deadline": Duration(),
    "liveliness": LivelinessPolicy.SYSTEM_DEFAULT,
    "liveliness_lease_duration": Duration(),
    "avoid_ros_namespace_conventions": False,
}


class QoSProfile:
    """Quality of Service policies of a publisher or subscription."""

    __slots__ = (
        "_avoid_ros_namespace_conventions",
        "_deadline",
        "_depth",
        "_durability",
        "_history",
        "_lifespan",
        "_liveliness",
        "_liveliness_lease_duration",
        "_reliability",
    )
    _FIELDS = (
        "history",
        "depth",
        "reliability",
        "durability",
        "lifespan",
        "deadline",
        "liveliness",
        "liveliness_lease_duration",
        "avoid_ros_namespace_conventions",
    )

    def __init__(
        self,
        history: HistoryPolicy | int | None = None,
        depth: int | None = None,
        reliability: ReliabilityPolicy | int | None = None,
        durability: DurabilityPolicy | int | None = None,
        lifespan: Duration | None = None,
        deadline: Duration | None = None,
        liveliness: LivelinessPolicy | int | None = None,
        liveliness_lease_duration: Duration | None = None,
        avoid_ros_namespace_conventions: bool | None = None,
    ) -> None:
        if history is None:
            if depth is None:
                raise InvalidQoSProfileException("History and/or depth settings are required.")
            history = HistoryPolicy.KEEP_LAST
        self.history = history
        if self.history == HistoryPolicy.KEEP_LAST and depth is None:
            raise InvalidQoSProfileException("History set to KEEP_LAST without a depth setting.")
        given = {
            "depth": depth,
            "reliability": reliability,
            "durability": durability,
            "lifespan": lifespan,
            "deadline": deadline,
            "liveliness": liveliness,
            "liveliness_lease_duration": liveliness_lease_duration,
            "avoid_ros_namespace_conventions": avoid_ros_namespace_conventions,
        }
        for name, value in given.items():
            setattr(self, name, _DEFAULTS[name] if value is None else value)

    @property
    def history(self) -> HistoryPolicy:
        return self._history

    @history.setter
    def history(self, value: HistoryPolicy | int) -> None:
        self._history = HistoryPolicy(value)

    @property
    def reliability(self) -> ReliabilityPolicy:
        return self._reliability

    @reliability.setter
    def reliability(self, value: ReliabilityPolicy | int) -> None:
        self._reliability = ReliabilityPolicy(value)

    @property
    def durability(self) -> DurabilityPolicy:
        return self._durability

    @durability.setter
    def durability(self, value: DurabilityPolicy | int) -> None:
        self._durability = DurabilityPolicy(value)

    @property
    def depth(self) -> int:
        return self._depth

    @depth.setter
    def depth(self, value: int) -> None:
        assert isinstance(value, int)
        if self.history == HistoryPolicy.KEEP_LAST and value == 0:
            warnings.warn(
                "A zero depth with KEEP_LAST doesn't make sense; no data could be stored. "
                "This will be interpreted as SYSTEM_DEFAULT",
                stacklevel=2,
            )
        self._depth = value

    @property
    def lifespan(self) -> Duration:
        return self._lifespan

    @lifespan.setter
    def lifespan(self, value: Duration) -> None:
        assert isinstance(value, Duration)
        self._lifespan = value

    @property
    def deadline(self) -> Duration:
        return self._deadline

    @deadline.setter
    def deadline(self, value: Duration) -> None:
        assert isinstance(value, Duration)
        self._deadline = value

    @property
    def liveliness(self) -> LivelinessPolicy:
        return self._liveliness

    @liveliness.setter
    def liveliness(self, value: LivelinessPolicy | int) -> None:
        self._liveliness = LivelinessPolicy(value)

    @property
    def liveliness_lease_duration(self) -> Duration:
        return self._liveliness_lease_duration

    @liveliness_lease_duration.setter
    def liveliness_lease_duration(self, value: Duration) -> None:
        assert isinstance(value, Duration)
        self._liveliness_lease_duration = value

    @property
    def avoid_ros_namespace_conventions(self) -> bool:
        return self._avoid_ros_namespace_conventions

    @avoid_ros_namespace_conventions.setter
    def avoid_ros_namespace_conventions(self, value: bool) -> None:
        assert isinstance(value, bool)
        self._avoid_ros_namespace_conventions = value

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, QoSProfile):
            return False
        return all(getattr(self, name) == getattr(other, name) for name in self._FIELDS)

    __hash__ = None  # type: ignore[assignment]

    def __str__(self) -> str:
        fields = ", ".join(f"{name}={getattr(self, name)}" for name in self._FIELDS)
        return f"QoSProfile({fields})"

    __repr__ = __str__

    # What a RoboDojo node does with the profile (module docstring).
    def queue_limit(self) -> int:
        """How many unread messages a subscription keeps."""
        if self.history == HistoryPolicy.KEEP_ALL:
            return KEEP_ALL_LIMIT
        return self.depth if self.depth > 0 else _DEFAULTS["depth"]

    def effective_reliability(self) -> ReliabilityPolicy:
        if self.reliability in (ReliabilityPolicy.BEST_EFFORT,):
            return ReliabilityPolicy.BEST_EFFORT
        return ReliabilityPolicy.RELIABLE  # system default, best available: reliable here

    def effective_durability(self) -> DurabilityPolicy:
        if self.durability == DurabilityPolicy.TRANSIENT_LOCAL:
            return DurabilityPolicy.TRANSIENT_LOCAL
        return DurabilityPolicy.VOLATILE


def _profile(**fields: Any) -> QoSProfile:
    return QoSProfile(**fields)


qos_profile_unknown = _profile(
    history=HistoryPolicy.UNKNOWN,
    depth=DEPTH_SYSTEM_DEFAULT,
    reliability=ReliabilityPolicy.UNKNOWN,
    durability=DurabilityPolicy.UNKNOWN,
    liveliness=LivelinessPolicy.UNKNOWN,
)
qos_profile_default = _profile(history=HistoryPolicy.KEEP_LAST, depth=10)
qos_profile_system_default = _profile(
    history=HistoryPolicy.SYSTEM_DEFAULT,
    depth=DEPTH_SYSTEM_DEFAULT,
    reliability=ReliabilityPolicy.SYSTEM_DEFAULT,
    durability=DurabilityPolicy.SYSTEM_DEFAULT,
)
qos_profile_sensor_data = _profile(
    history=HistoryPolicy.KEEP_LAST,
    depth=5,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)
qos_profile_services_default = _profile(history=HistoryPolicy.KEEP_LAST, depth=10)
qos_profile_parameters = _profile(history=HistoryPolicy.KEEP_LAST, depth=1000)
qos_profile_parameter_events = _profile(history=HistoryPolicy.KEEP_LAST, depth=1000)
qos_profile_best_available = _profile(
    history=HistoryPolicy.KEEP_LAST,
    depth=10,
    reliability=ReliabilityPolicy.BEST_AVAILABLE,
    durability=DurabilityPolicy.BEST_AVAILABLE,
    liveliness=LivelinessPolicy.BEST_AVAILABLE,
)
qos_profile_action_status_default = _profile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)


class QoSPresetProfiles(Enum):
    UNKNOWN = qos_profile_unknown
    DEFAULT = qos_profile_default
    SYSTEM_DEFAULT = qos_profile_system_default
    SENSOR_DATA = qos_profile_sensor_data
    SERVICES_DEFAULT = qos_profile_services_default
    PARAMETERS = qos_profile_parameters
    PARAMETER_EVENTS = qos_profile_parameter_events
    ACTION_STATUS_DEFAULT = qos_profile_action_status_default
    BEST_AVAILABLE = qos_profile_best_available

    @classmethod
    def short_keys(cls) -> list[str]:
        return [key.lower() for key in cls.__members__]

    @classmethod
    def get_from_short_key(cls, name: str) -> QoSProfile:
        return cls[name.upper()].value


class QoSCompatibility(IntEnum):
    OK = 0
    WARNING = 1
    ERROR = 2


def incompatible_policy(
    publisher_reliability: ReliabilityPolicy,
    publisher_durability: DurabilityPolicy,
    subscription_qos: QoSProfile,
) -> QoSPolicyKind | None:
    """The policy that keeps a publisher's messages from a subscription, or None."""
    if (
        publisher_reliability == ReliabilityPolicy.BEST_EFFORT
        and subscription_qos.effective_reliability() == ReliabilityPolicy.RELIABLE
    ):
        return QoSPolicyKind.RELIABILITY
    if (
        publisher_durability == DurabilityPolicy.VOLATILE
        and subscription_qos.effective_durability() == DurabilityPolicy.TRANSIENT_LOCAL
    ):
        return QoSPolicyKind.DURABILITY
    return None


def qos_check_compatible(
    publisher_qos: QoSProfile, subscription_qos: QoSProfile
) -> tuple[QoSCompatibility, str]:
    """rmw_qos_profile_check_compatible, for the policies that matter here."""
    kind = incompatible_policy(
        publisher_qos.effective_reliability(),
        publisher_qos.effective_durability(),
        subscription_qos,
    )
    if kind == QoSPolicyKind.RELIABILITY:
        return QoSCompatibility.ERROR, "ERROR: Best effort publisher and reliable subscription;"
    if kind == QoSPolicyKind.DURABILITY:
        return (
            QoSCompatibility.ERROR,
            "ERROR: Volatile publisher and transient local subscription;",
        )
    return QoSCompatibility.OK, ""
