"""Running a batch on a Dask distributed cluster: the one module that talks to Dask.

The engine is a task of its own (so a worker that joins late, or replaces a lost one, can
have it recomputed); each chunk of configurations is a task depending on it. At most a few
chunks per worker are in flight and their rows come back in chunk order, so the output is
the single-process output, byte for byte. A worker lost mid-batch loses nothing: the
scheduler reruns its chunks on another worker.
"""

from __future__ import annotations

import contextlib
import re
from collections import deque
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

from plugnproduce.batch.batches import Configuration, Engine, Mapper, Part, run_chunk
from plugnproduce.batch.clusterpeer import ClusterAccess, ClusterError, probe

if TYPE_CHECKING:
    from distributed import Client

LOCAL = re.compile(r"local:(\d{1,3})")
REMOTE = re.compile(r"(tcp|tls|ws|wss|inproc)://\S+")
RETRIES = 3
"""Reruns of a chunk whose task raised (a lost worker is handled by the scheduler on top)."""


def check_address(address: str) -> str:
    """The address if it is ``local:N`` (N ≥ 1) or a scheduler URL; ValueError saying what is expected."""
    local = LOCAL.fullmatch(address)
    if (local and int(local.group(1)) >= 1) or REMOTE.fullmatch(address):
        return address
    raise ValueError(f"expected a scheduler address such as tcp://HOST:8786, or local:N; found {address!r}")


def cluster_mapper(cluster: str | ClusterAccess) -> Mapper:
    """A :data:`.batches.Mapper` that runs chunks on the cluster at an address (see :func:`check_address`),
    connecting within its timeout, with its TLS files for ``tls://``, to a peer checked first
    (:func:`~.clusterpeer.probe`)."""
    access = cluster if isinstance(cluster, ClusterAccess) else ClusterAccess(cluster)
    check_address(access.address)
    access.check()

    def run(engine: Engine, chunks: Iterator[list[Configuration]], form: str) -> Iterator[Part]:
        with _client(access) as client:
            yield from _ordered(client, engine, chunks, form)

    return run


@contextlib.contextmanager
def _client(access: ClusterAccess) -> Iterator[Client]:
    import dask
    from distributed import Client, LocalCluster

    local = LOCAL.fullmatch(access.address)
    if local is None:
        probe(access)
        with dask.config.set({"distributed.comm.timeouts.connect": f"{access.timeout}s"}):
            try:
                client = Client(access.address, timeout=access.timeout,  # type: ignore[no-untyped-call]
                                security=access.security())
            except (OSError, TimeoutError, ValueError) as exc:
                raise ClusterError(f"--cluster {access.address}: cannot connect ({exc})") from exc
        with client:
            yield client
        return
    workers = int(local.group(1))
    with (LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,  # type: ignore[no-untyped-call]
                       dashboard_address=None) as cluster,
          Client(cluster) as client):  # type: ignore[no-untyped-call]
        yield client


def _ordered(client: Client, engine: Engine, chunks: Iterator[list[Configuration]], form: str) -> Iterator[Part]:
    shared = client.submit(_same, engine, pure=False)
    window = 2 * max(1, len(client.scheduler_info().get("workers", {})))
    pending: deque[Any] = deque()
    for chunk in chunks:
        pending.append(client.submit(run_chunk, chunk, form, shared, retries=RETRIES, pure=False))
        if len(pending) >= window:
            yield pending.popleft().result()
    while pending:
        yield pending.popleft().result()


def _same(engine: Engine) -> Engine:
    return engine
