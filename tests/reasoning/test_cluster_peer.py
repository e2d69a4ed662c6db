"""``--cluster`` checked: a silent peer or one that is no Dask scheduler is one line, and TLS works with the
certificates the test makes itself."""

from __future__ import annotations

import gc
import socket
import subprocess
import threading
import warnings
from collections.abc import Iterator
from pathlib import Path

import pytest
from distributed import LocalCluster, Security
from typer.testing import CliRunner

from plugnproduce.cli import app
from tests.reasoning.conftest import TASKS

runner = CliRunner()
ARGS = ["batch", "--generate", "40", "--sizes", "0-5", "--seed", "3", "--task", str(TASKS / "pick-and-place.yaml")]


class Peer:
    """A TCP peer on loopback that accepts and says nothing (``greeting=b""``) or sends ``greeting``."""

    def __init__(self, greeting: bytes) -> None:
        self.greeting = greeting
        self.server = socket.create_server(("127.0.0.1", 0))
        self.server.settimeout(0.2)
        self.address = f"tcp://127.0.0.1:{self.server.getsockname()[1]}"
        self._stop = threading.Event()
        self._held: list[socket.socket] = []
        self._thread = threading.Thread(target=self._serve, daemon=True)

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self.server.accept()
            except TimeoutError:
                continue
            self._held.append(conn)
            if self.greeting:
                conn.sendall(self.greeting)

    def __enter__(self) -> Peer:
        self._thread.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._stop.set()
        self._thread.join(10)
        for conn in self._held:
            conn.close()
        self.server.close()


@pytest.mark.parametrize("greeting, says", [
    (b"", "no Dask greeting within 1 s (a silent peer, or no scheduler)"),
    (b"\xff" * 64, "the peer is no Dask scheduler (its first message claims 18446744073709551615 bytes"),
    (b"HTTP/1.1 200 OK\r\nContent-Length: 2\r\n\r\nok", "the peer is no Dask scheduler (its first message claims"),
    (b"\x10\x00\x00\x00\x00\x00\x00\x00" + b"\x01" * 16, "the peer is no Dask scheduler (its first message is no"),
], ids=["silent", "garbage", "http", "short garbage"])
def test_issue_24_a_cluster_peer_that_is_no_scheduler_is_one_line(greeting: bytes, says: str) -> None:
    # a silent peer hung the batch for 103 s; garbage gave an 82-line traceback allocating 3 EiB
    with Peer(greeting) as peer:
        result = runner.invoke(app, [*ARGS, "--cluster", peer.address, "--cluster-timeout", "1"])
    assert result.exit_code == 2
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"error: --cluster {peer.address}: {says}"), line
    assert result.stdout == ""


def test_a_cluster_address_where_nothing_listens_is_one_line() -> None:
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
    result = runner.invoke(app, [*ARGS, "--cluster", f"tcp://127.0.0.1:{port}"])
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [f"error: --cluster tcp://127.0.0.1:{port}: cannot connect (Connection "
                                          "refused)"]


def _openssl(*args: str) -> None:
    subprocess.run(["openssl", *args], check=True, capture_output=True, timeout=120)


@pytest.fixture(scope="module")
def certificates(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A CA of the test's own, and a certificate and key for the scheduler, the worker and the client, signed
    by it; and a second CA that signed nothing of this cluster."""
    d = tmp_path_factory.mktemp("tls")
    for ca in ("ca", "other-ca"):
        _openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", str(d / f"{ca}.key"), "-out",
                 str(d / f"{ca}.pem"), "-days", "2", "-subj", f"/CN=plugnproduce test {ca}")
    _openssl("req", "-newkey", "rsa:2048", "-nodes", "-keyout", str(d / "node.key"), "-out", str(d / "node.csr"),
             "-subj", "/CN=127.0.0.1")
    _openssl("x509", "-req", "-in", str(d / "node.csr"), "-CA", str(d / "ca.pem"), "-CAkey", str(d / "ca.key"),
             "-CAcreateserial", "-out", str(d / "node.pem"), "-days", "2")
    return {"ca": d / "ca.pem", "other-ca": d / "other-ca.pem", "cert": d / "node.pem", "key": d / "node.key"}


@pytest.fixture(scope="module")
def tls_cluster(certificates: dict[str, Path]) -> Iterator[str]:
    ca, cert, key = (str(certificates[k]) for k in ("ca", "cert", "key"))
    with warnings.catch_warnings():  # a socket an earlier test of this worker left to the collector is not ours
        warnings.simplefilter("ignore", ResourceWarning)
        gc.collect()
    security = Security(tls_ca_file=ca, tls_scheduler_cert=cert, tls_scheduler_key=key, tls_worker_cert=cert,
                        tls_worker_key=key, tls_client_cert=cert, tls_client_key=key, require_encryption=True)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, protocol="tls://", host="127.0.0.1",
                      security=security, dashboard_address="127.0.0.1:0") as cluster:  # 8787 may be taken
        yield cluster.scheduler_address


def test_issue_24_a_tls_cluster_gives_the_rows_of_one_process(tls_cluster: str, certificates: dict[str, Path]) -> None:
    alone = runner.invoke(app, [*ARGS, "--workers", "1"])
    tls = ["--cluster-ca", str(certificates["ca"]), "--cluster-cert", str(certificates["cert"]),
           "--cluster-key", str(certificates["key"])]
    spread = runner.invoke(app, [*ARGS, "--cluster", tls_cluster, *tls, "--cluster-timeout", "60"])
    assert alone.exit_code == spread.exit_code == 0, spread.output
    assert spread.stdout == alone.stdout and len(alone.stdout.splitlines()) == 40


def test_a_tls_cluster_whose_certificate_another_ca_signed_is_refused_in_one_line(
        tls_cluster: str, certificates: dict[str, Path]) -> None:
    tls = ["--cluster-ca", str(certificates["other-ca"]), "--cluster-cert", str(certificates["cert"]),
           "--cluster-key", str(certificates["key"])]
    result = runner.invoke(app, [*ARGS, "--cluster", tls_cluster, *tls, "--cluster-timeout", "60"])
    assert result.exit_code == 2
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"error: --cluster {tls_cluster}: the TLS handshake failed (CERTIFICATE_VERIFY_FAILED")


def test_a_tls_address_without_its_files_is_bad_input() -> None:
    result = runner.invoke(app, [*ARGS, "--cluster", "tls://127.0.0.1:8786"])
    assert result.exit_code == 2
    assert result.stderr.splitlines() == ["--cluster: a tls:// address needs --cluster-ca, --cluster-cert and "
                                          "--cluster-key"]


def test_tls_files_with_a_tcp_address_are_bad_input(certificates: dict[str, Path]) -> None:
    result = runner.invoke(app, [*ARGS, "--cluster", "tcp://127.0.0.1:8786", "--cluster-ca", str(certificates["ca"])])
    assert result.exit_code == 2
    assert result.stderr.startswith("--cluster: --cluster-ca, --cluster-cert and --cluster-key are for a tls:// ")
