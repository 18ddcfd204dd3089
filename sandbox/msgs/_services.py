"""ROS 1 service types: a pair of message classes under one name and md5sum.

Shaped as genpy generates them (``std_srvs/srv/_SetBool.py``): the service class ``SetBool``
carries ``_type``, ``_md5sum``, ``_request_class`` and ``_response_class``; ``SetBoolRequest`` and
``SetBoolResponse`` are ordinary messages (types ``std_srvs/SetBoolRequest`` and
``std_srvs/SetBoolResponse``, each with its own md5sum). The service md5sum hashes the request's
and then the response's md5 text in one digest, as genmsg's ``gentools.compute_md5`` does for a
``SrvSpec``. Built on first use, like the messages.
"""

from __future__ import annotations

from typing import ClassVar

from ._catalog import SRV, unknown_type_sentence
from ._core import _BUILD_LOCK, Message, UnknownMessageTypeError, get_message_class
from ._definitions import SERVICES
from ._spec import compute_service_md5


class UnknownServiceTypeError(UnknownMessageTypeError):
    """``get_service_class`` was given a name that is not a service RoboDojo provides."""


class Service:
    """Base of every service class; not instantiated (rospy uses the class as a type)."""

    __slots__ = ()

    _type: ClassVar[str]
    _md5sum: ClassVar[str]
    _request_class: ClassVar[type[Message]]
    _response_class: ClassVar[type[Message]]


_SERVICES: dict[str, type[Service]] = {}


def get_service_class(srv_type: str) -> type[Service]:
    """The class of ``"pkg/Name"``, e.g. ``get_service_class("std_srvs/SetBool")``."""
    cls = _SERVICES.get(srv_type)
    if cls is not None:
        return cls
    if srv_type not in SERVICES:
        raise UnknownServiceTypeError(unknown_type_sentence(srv_type, SRV))
    with _BUILD_LOCK:
        cls = _SERVICES.get(srv_type)
        if cls is None:
            request = get_message_class(f"{srv_type}Request")
            response = get_message_class(f"{srv_type}Response")
            package, name = srv_type.split("/")
            namespace = {
                "__module__": f"sandbox.msgs.{package}",
                "__qualname__": name,
                "__slots__": (),
                "_type": srv_type,
                "_md5sum": compute_service_md5(request, response),
                "_request_class": request,
                "_response_class": response,
            }
            cls = _SERVICES[srv_type] = type(name, (Service,), namespace)
        return cls
