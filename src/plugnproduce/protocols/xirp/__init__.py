"""XIRP for Plug'n'Produce devices: XML messages over TCP, modelled on VDMA 66430.

* :mod:`~plugnproduce.protocols.xirp.messages`: the message set as plain data.
* :mod:`~plugnproduce.protocols.xirp.codec`: framing, encoding, hardened decoding
  validated against the shipped schema ``xirp.xsd``.
* Device side: :class:`XirpServer` (with :class:`Faults` to misbehave on purpose).
* Controller side: :class:`XirpClient`.

See ``docs/xirp.md``.
"""

from __future__ import annotations

from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.protocols.xirp.answer import RequestFailed, RequestHandler, Results
from plugnproduce.protocols.xirp.client import RemoteFailure, XirpClient
from plugnproduce.protocols.xirp.codec import MAX_FRAME, encode, encode_frame, frame
from plugnproduce.protocols.xirp.decoding import decode, schema
from plugnproduce.protocols.xirp.faults import FaultKind, FaultRule, Faults
from plugnproduce.protocols.xirp.inbox import EventCallback, LinkStats
from plugnproduce.protocols.xirp.messages import (
    BAD_PARAMETER,
    DESCRIBE,
    FAILED,
    MALFORMED,
    NAMESPACE,
    NOT_ACCEPTED,
    STATE,
    STATE_RESULT,
    TOO_LARGE,
    UNEXPECTED,
    UNKNOWN_REQUEST,
    Bye,
    Document,
    ErrorMessage,
    Event,
    Failure,
    Hello,
    Message,
    MessageError,
    Params,
    Pose,
    Request,
    Response,
    Value,
    documents_of,
    files_from_documents,
    format_endpoint,
    parse_endpoint,
)
from plugnproduce.protocols.xirp.server import XirpServer

__all__ = [
    "BAD_PARAMETER",
    "DESCRIBE",
    "FAILED",
    "MALFORMED",
    "MAX_FRAME",
    "NAMESPACE",
    "NOT_ACCEPTED",
    "STATE",
    "STATE_RESULT",
    "TOO_LARGE",
    "UNEXPECTED",
    "UNKNOWN_REQUEST",
    "Bye",
    "DeviceFiles",
    "documents_of",
    "files_from_documents",
    "Document",
    "ErrorMessage",
    "Event",
    "EventCallback",
    "Failure",
    "FaultRule",
    "FaultKind",
    "Faults",
    "Hello",
    "LinkStats",
    "Message",
    "MessageError",
    "Params",
    "Pose",
    "RemoteFailure",
    "Request",
    "RequestFailed",
    "RequestHandler",
    "Results",
    "Response",
    "Value",
    "XirpClient",
    "XirpServer",
    "decode",
    "encode",
    "encode_frame",
    "format_endpoint",
    "frame",
    "parse_endpoint",
    "schema",
]
