"""The user identity the controller gives an OPC UA device that asks for one: a user name and a password.

They come from a **users file**, named by ``PNP_OPCUA_USERS`` (else ``PKI/users`` in the PKI folder, if there is
one): one device a line, ``DEVICE USER PASSWORD`` (the password is the rest of the line), ``*`` for every
device not named on a line of its own; blank lines and lines starting with ``#`` say nothing. Keep it readable
by the controller's user only: it holds passwords. Without a line for a device its session is anonymous.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from plugnproduce.errors import ProtocolError

MAX_USERS_FILE = 64 * 1024
"""Largest users file (bytes) the controller reads."""
ANY = "*"
"""The device name of the line that holds for every device without a line of its own."""


@dataclass(frozen=True)
class UserIdentity:
    """A user name and password for one device, and the file that gave them."""

    user: str
    password: str
    source: Path

    def __repr__(self) -> str:  # never show the password, in a log or a traceback
        return f"UserIdentity(user={self.user!r}, source={str(self.source)!r})"


def identity_for(users: Path | None, device: str) -> UserIdentity | None:
    """The identity ``users`` gives ``device`` (its own line, else the ``*`` line), or None: anonymous."""
    if users is None:
        return None
    lines = _lines(users)
    found = lines.get(device) or lines.get(ANY)
    return UserIdentity(found[0], found[1], users) if found is not None else None


def _lines(users: Path) -> dict[str, tuple[str, str]]:
    try:
        with users.open("rb") as f:
            data = f.read(MAX_USERS_FILE + 1)
    except OSError as exc:
        raise ProtocolError(f"{users}: cannot read the OPC UA users file: {exc.strerror or exc}") from exc
    if len(data) > MAX_USERS_FILE:
        raise ProtocolError(f"{users}: the OPC UA users file is larger than {MAX_USERS_FILE} bytes")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ProtocolError(f"{users}: the OPC UA users file is not UTF-8 text") from exc
    found: dict[str, tuple[str, str]] = {}
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        fields = line.split(None, 2)
        if len(fields) < 3 or not fields[2].strip():
            raise ProtocolError(f"{users}:{number}: expected DEVICE USER PASSWORD (DEVICE may be {ANY})")
        found.setdefault(fields[0], (fields[1], fields[2].strip()))
    return found
