"""Whom ``--cluster`` connects to: the address, its TLS files, and a check of the peer before Dask trusts it.

Dask's comms take a message's length from the peer and allocate it: a peer that is no Dask
scheduler and answers garbage makes the client allocate exabytes, and a silent one keeps it
waiting. So before a :class:`distributed.Client` connects, :func:`probe` opens the connection
itself, within the timeout, and reads the greeting a Dask scheduler sends first: it must be a
short, well-formed Dask handshake. A cluster address is trusted code execution all the same:
the scheduler runs what the batch sends it, and the client unpickles what comes back.
"""

from __future__ import annotations

import socket
import ssl
import struct
import time
from dataclasses import dataclass
from pathlib import Path

from plugnproduce.errors import PlugNProduceError, excerpt

CONNECT_SECONDS = 10.0
"""Seconds connecting to a cluster (and reading its greeting) may take, unless told."""
MAX_GREETING = 64 * 1024
"""Largest greeting accepted from a scheduler (Dask's is under 100 bytes)."""


class ClusterError(PlugNProduceError):
    """The cluster at an address cannot be used: it does not answer, answers as no Dask scheduler, or refuses TLS."""


@dataclass(frozen=True)
class ClusterAccess:
    """A Dask scheduler's address (``tcp://``, ``tls://`` or ``local:N``), the connect timeout, and for ``tls://``
    the CA certificate that signed the scheduler's, and this client's certificate and key."""

    address: str
    timeout: float = CONNECT_SECONDS
    ca: Path | None = None
    cert: Path | None = None
    key: Path | None = None

    def check(self) -> None:
        """ValueError unless the TLS files fit the address: all three for ``tls://``, none otherwise."""
        files = (self.ca, self.cert, self.key)
        tls = self.address.startswith("tls://")
        if tls and None in files:
            raise ValueError("a tls:// address needs --cluster-ca, --cluster-cert and --cluster-key")
        if not tls and any(f is not None for f in files):
            raise ValueError(f"--cluster-ca, --cluster-cert and --cluster-key are for a tls:// address; "
                             f"found {excerpt(self.address)!r}")
        for f in files:
            if f is not None and not f.is_file():
                raise ValueError(f"{f}: file not found")

    def security(self) -> object | None:
        """Dask's :class:`distributed.Security` for a ``tls://`` address (None for another)."""
        if self.ca is None:
            return None
        from distributed import Security

        return Security(tls_ca_file=str(self.ca), tls_client_cert=str(self.cert),  # type: ignore[no-untyped-call]
                        tls_client_key=str(self.key), require_encryption=True)

    def ssl_context(self) -> ssl.SSLContext:
        """The TLS context :func:`probe` connects with: the scheduler verified by the CA, this client by its
        certificate (as Dask does, the host name is not checked: the CA is the cluster's own)."""
        context = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
        context.check_hostname = False
        context.load_verify_locations(cafile=str(self.ca))
        context.load_cert_chain(str(self.cert), str(self.key))
        return context


def probe(access: ClusterAccess) -> None:
    """Connect to ``access.address`` and read a Dask scheduler's greeting within ``access.timeout`` seconds;
    :class:`ClusterError` saying what was found instead. Addresses other than ``tcp://`` and ``tls://``
    are left to Dask (with its connect timeout)."""
    scheme, _, rest = access.address.partition("://")
    if scheme not in ("tcp", "tls"):
        return
    host, _, port = rest.rstrip("/").rpartition(":")
    where = f"--cluster {excerpt(access.address)}"
    if not host or not port.isdigit():
        raise ClusterError(f"{where}: expected {scheme}://HOST:PORT")
    deadline = time.monotonic() + access.timeout
    try:
        sock = socket.create_connection((host.strip("[]"), int(port)), timeout=access.timeout)
    except TimeoutError:
        raise ClusterError(f"{where}: no connection within {access.timeout:g} s") from None
    except OSError as exc:
        raise ClusterError(f"{where}: cannot connect ({exc.strerror or exc})") from None
    try:
        if scheme == "tls":
            sock = _tls(sock, access, where)
        _greeting(sock, deadline, where, access.timeout)
    finally:
        sock.close()


def _tls(sock: socket.socket, access: ClusterAccess, where: str) -> socket.socket:
    try:
        return access.ssl_context().wrap_socket(sock)
    except TimeoutError:
        raise ClusterError(f"{where}: no TLS handshake within {access.timeout:g} s") from None
    except (ssl.SSLError, OSError) as exc:
        raise ClusterError(f"{where}: the TLS handshake failed ({getattr(exc, 'reason', None) or exc})") from None


def _greeting(sock: socket.socket, deadline: float, where: str, timeout: float) -> None:
    """Read the scheduler's first message (its handshake) and check that it is one."""
    (size,) = struct.unpack("Q", _read(sock, 8, deadline, where, timeout))  # as distributed.comm.tcp reads it
    if size > MAX_GREETING:
        raise ClusterError(f"{where}: the peer is no Dask scheduler (its first message claims {size} bytes; "
                           f"a scheduler's greeting is under {MAX_GREETING})")
    body = _read(sock, size, deadline, where, timeout)
    try:
        from distributed.protocol.core import loads
        from distributed.protocol.utils import unpack_frames

        frames, rest = unpack_frames(body, partial=True)
        message = loads(frames, deserialize=False) if not rest else None  # type: ignore[no-untyped-call]
    except Exception:  # noqa: BLE001 - whatever the peer sent, it is no greeting
        message = None
    if not isinstance(message, dict) or "compression" not in message:
        raise ClusterError(f"{where}: the peer is no Dask scheduler (its first message is no Dask handshake)")


def _read(sock: socket.socket, n: int, deadline: float, where: str, timeout: float) -> bytes:
    data = b""
    while len(data) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            raise ClusterError(f"{where}: no Dask greeting within {timeout:g} s (a silent peer, or no scheduler)")
        sock.settimeout(left)
        try:
            chunk = sock.recv(n - len(data))
        except TimeoutError:
            raise ClusterError(f"{where}: no Dask greeting within {timeout:g} s (a silent peer, or no "
                               "scheduler)") from None
        except OSError as exc:
            raise ClusterError(f"{where}: the connection failed ({exc.strerror or exc})") from None
        if not chunk:
            raise ClusterError(f"{where}: the peer closed the connection before greeting as a Dask scheduler")
        data += chunk
    return data
