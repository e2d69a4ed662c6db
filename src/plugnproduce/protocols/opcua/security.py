"""OPC UA security at the device-facing edge: the security mode, the PKI folder and the certificates.

Security mode ``None`` sends everything in the clear and proves nobody's identity, so the controller uses it only
for a device on loopback, unless ``PNP_OPCUA_ALLOW_INSECURE=1`` says otherwise. ``Sign`` and ``SignAndEncrypt``
(policy Basic256Sha256) need a **PKI folder** (``PNP_OPCUA_PKI``)::

    PKI/own/cert.der, PKI/own/key.pem          the controller's certificate (DER) and private key (PEM)
    PKI/trusted/*.der                          the device certificates the controller trusts
    PKI/devices/ID/cert.der, .../key.pem       a simulated device's certificate and key
    PKI/clients/*.der                          the client certificates the simulated devices trust

:func:`generate` fills a folder with self-signed certificates (asyncua's own helpers): the controller's, one per
simulated device, each trusted by the other side. See ``docs/opcua.md``.
"""

from __future__ import annotations

import ipaddress
import os
import shutil
import socket
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from plugnproduce.errors import ProtocolError
from plugnproduce.protocols.opcua.identity import UserIdentity, identity_for
from plugnproduce.protocols.opcua.spec import application_uri_for

MODES = ("None", "Sign", "SignAndEncrypt")
"""The security modes, all with the policy Basic256Sha256 but ``None``."""
MAX_TRUSTED = 4096
"""Most certificates a trusted folder may hold."""
CONTROLLER_URI = "urn:plugnproduce:controller"
"""The application URI of the controller's client (in its certificate)."""


@dataclass(frozen=True)
class Security:
    """The security mode and PKI folder one side uses; ``Security()`` is mode None on loopback only."""

    mode: str = "None"
    pki: Path | None = None
    allow_insecure: bool = False
    """Mode None also for a device off loopback (``PNP_OPCUA_ALLOW_INSECURE=1``)."""
    users: Path | None = None
    """The users file: the user names and passwords of the devices that ask for one (:mod:`.identity`)."""

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ProtocolError(f"OPC UA security mode {self.mode!r} is unknown; expected {', '.join(MODES)}")
        if self.mode != "None" and self.pki is None:
            raise ProtocolError(f"OPC UA security mode {self.mode} needs a PKI folder (PNP_OPCUA_PKI)")


def from_environment(env: Mapping[str, str] | None = None) -> Security:
    """``PNP_OPCUA_SECURITY`` (default SignAndEncrypt with a PKI folder, else None), ``PNP_OPCUA_PKI``,
    ``PNP_OPCUA_ALLOW_INSECURE`` and ``PNP_OPCUA_USERS`` (default ``PKI/users`` where it exists)."""
    env = os.environ if env is None else env
    pki = Path(env["PNP_OPCUA_PKI"]) if env.get("PNP_OPCUA_PKI") else None
    mode = env.get("PNP_OPCUA_SECURITY") or ("SignAndEncrypt" if pki is not None else "None")
    users = Path(env["PNP_OPCUA_USERS"]) if env.get("PNP_OPCUA_USERS") else None
    if users is None and pki is not None and (pki / "users").is_file():
        users = pki / "users"
    return Security(mode, pki, env.get("PNP_OPCUA_ALLOW_INSECURE", "") in ("1", "yes", "true"), users)


def is_loopback(host: str) -> bool:
    """Whether ``host`` (an address or ``localhost``) is this machine's loopback."""
    if host.lower() in ("localhost", "localhost."):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def check_plain(security: Security, device: str, endpoint: str, host: str) -> None:
    """Refuse mode None for a device off loopback unless it is allowed explicitly."""
    if security.mode == "None" and not security.allow_insecure and not is_loopback(host):
        raise ProtocolError(f"device {device}: {endpoint} is not on loopback and security mode None would send "
                            "in the clear; set PNP_OPCUA_PKI (Sign or SignAndEncrypt), or allow it with "
                            "PNP_OPCUA_ALLOW_INSECURE=1")


def _mode(security: Security) -> Any:
    from asyncua import ua

    return getattr(ua.MessageSecurityMode, security.mode)


def _own(pki: Path, device: str | None) -> tuple[Path, Path]:
    folder = pki / "own" if device is None else pki / "devices" / device
    return folder / "cert.der", folder / "key.pem"


def _readable(path: Path, what: str) -> Path:
    if not path.is_file():
        raise ProtocolError(f"{path}: no {what}; make one, or let 'pnp sim up' generate the folder")
    return path


def _service_error() -> type[Exception]:
    from asyncua.common.utils import ServiceError

    return ServiceError  # type: ignore[no-any-return]


class PeerRefused(_service_error()):  # type: ignore[misc]
    """This side refused the peer's certificate (not the peer ours): asyncua's ServiceError, told apart."""


async def _validator(trusted: Path, peer: str) -> Any:
    """A certificate validator: valid now, naming the peer's application URI, and one of the certificates
    (DER) in ``trusted`` itself (each trusted certificate is pinned; no chains of authorities)."""
    from asyncua import ua
    from asyncua.common.utils import ServiceError
    from asyncua.crypto.validator import CertificateValidator
    from asyncua.crypto.validator import CertificateValidatorOptions as O  # noqa: N817
    from cryptography.hazmat.primitives.serialization import Encoding

    pinned = {p.read_bytes() for p in sorted(trusted.glob("*.der"))[:MAX_TRUSTED] if p.is_file()}
    role = O.PEER_SERVER if peer == "server" else O.PEER_CLIENT
    checks = CertificateValidator(O.TIME_RANGE | O.URI | role)

    async def validate(certificate: Any, application: Any) -> None:
        try:
            await checks.validate(certificate, application)
        except ServiceError as exc:
            raise PeerRefused(exc.code) from exc
        if certificate.public_bytes(Encoding.DER) not in pinned:
            raise PeerRefused(ua.StatusCodes.BadCertificateUntrusted)

    return validate


async def secure_client(client: Any, security: Security, device: str) -> UserIdentity | None:
    """Give an asyncua client the controller's certificate and key, and trust only the folder's device
    certificates (an untrusted server is refused with ``BadCertificateUntrusted``); and the user identity the
    users file gives ``device``, returned (None: the session is anonymous)."""
    identity = identity_for(security.users, device)
    if identity is not None:
        client.set_user(identity.user)
        client.set_password(identity.password)
    if security.mode == "None" or security.pki is None:
        return identity
    from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256

    cert, key = _own(security.pki, None)
    client.application_uri = CONTROLLER_URI
    client.certificate_validator = await _validator(security.pki / "trusted", "server")
    await client.set_security(SecurityPolicyBasic256Sha256, str(_readable(cert, "controller certificate")),
                              str(_readable(key, "controller private key")), mode=_mode(security))
    return identity


async def secure_server(server: Any, security: Security, device: str) -> None:
    """Let a device's asyncua server offer only ``security.mode`` with its own certificate, and take only
    the clients whose certificates the folder trusts; mode None: the server offers no security."""
    from asyncua import ua

    if security.mode == "None" or security.pki is None:
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
        return
    cert, key = _own(security.pki, device)
    policy = (ua.SecurityPolicyType.Basic256Sha256_Sign if security.mode == "Sign"
              else ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt)
    server.set_security_policy([policy])
    await server.load_certificate(str(_readable(cert, f"certificate of device {device}")))
    await server.load_private_key(str(_readable(key, f"private key of device {device}")))
    server.set_certificate_validator(await _validator(security.pki / "clients", "client"))


async def generate(pki: Path, devices: Iterable[str]) -> None:
    """Make the missing certificates of ``pki``: the controller's and each device's (self-signed, a year),
    each trusted by the other side. Existing keys and valid certificates are kept."""
    from asyncua.crypto.cert_gen import setup_self_signed_certificate
    from cryptography.x509.oid import ExtendedKeyUsageOID

    host = socket.gethostname()
    for folder in ("own", "trusted", "clients"):
        (pki / folder).mkdir(parents=True, exist_ok=True)
    cert, key = _own(pki, None)
    await setup_self_signed_certificate(key, cert, CONTROLLER_URI, host, [ExtendedKeyUsageOID.CLIENT_AUTH],
                                        {"commonName": "Plug'n'Produce controller"})
    shutil.copyfile(cert, pki / "clients" / "controller.der")
    for device in devices:
        cert, key = _own(pki, device)
        cert.parent.mkdir(parents=True, exist_ok=True)
        await setup_self_signed_certificate(key, cert, application_uri_for(device), host,
                                            [ExtendedKeyUsageOID.SERVER_AUTH], {"commonName": device})
        shutil.copyfile(cert, pki / "trusted" / f"{device}.der")


async def device_security(device: str) -> Security:
    """A simulated device's security from the environment; with a PKI folder, its missing certificates made."""
    security = from_environment()
    if security.pki is not None:
        await generate(security.pki, [device])
    return security
