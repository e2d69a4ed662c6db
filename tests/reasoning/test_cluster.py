"""``pnp batch --cluster``: a Dask cluster gives the single process's rows, in order, and loses none."""

from __future__ import annotations

import os
import signal
from collections.abc import Iterator

import pytest
from distributed import Client, LocalCluster
from typer.testing import CliRunner

from plugnproduce import service
from plugnproduce.batch import BatchRow, batch, cluster_mapper, generate
from plugnproduce.cli import app
from tests.reasoning.conftest import TASKS

runner = CliRunner()
ARGS = ["batch", "--generate", "3000", "--sizes", "0-7", "--seed", "4", "--top", "2",
        "--task", str(TASKS / "bin-picking.yaml"), "--task", str(TASKS / "pick-and-place.yaml")]


def test_a_local_cluster_writes_the_bytes_one_process_writes() -> None:
    alone = runner.invoke(app, [*ARGS, "--workers", "1"])
    spread = runner.invoke(app, [*ARGS, "--cluster", "local:2"])
    assert alone.exit_code == spread.exit_code == 0, spread.output
    assert spread.stdout == alone.stdout and len(alone.stdout.splitlines()) == 3000


@pytest.fixture
def cluster() -> Iterator[LocalCluster]:
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        yield c


def test_a_worker_killed_mid_batch_loses_no_configuration(cluster: LocalCluster) -> None:
    k = service.knowledge()
    tasks = [service.task(TASKS / "bin-picking.yaml"), service.task(TASKS / "pick-and-place.yaml")]
    configs = list(generate(list(k.devices), 20_000, (0, 7), seed=9))

    def run(mapper: object = None) -> Iterator[BatchRow]:
        return batch(configs, list(k.devices), tasks, k, workers=1, chunk=100,
                     mapper=mapper)  # type: ignore[arg-type]

    with Client(cluster) as client:
        pids = client.run(os.getpid)
    rows = run(cluster_mapper(cluster.scheduler_address))
    got = [next(rows)]
    os.kill(next(iter(pids.values())), signal.SIGKILL)
    got += list(rows)
    assert got == list(run())
    with Client(cluster) as client:
        assert set(client.run(os.getpid).values()) != set(pids.values())  # the killed worker was replaced
