"""Benchmark of the SHACL shapes run (prints figures; not a test).

    python bench/bench_shapes.py [--rounds 5]

The data graphs ``pnp validate`` builds for two inputs (one shipped task; every built-in
description), each run through the shapes by :func:`shape_problems` (each SPARQL constraint's
text parsed once) and by the plain pySHACL call it made before (the data graph copied, the
text parsed again for every focus node), in the same run, warm (each run once before timing),
CPU time, best of the rounds; both must give the same problems.
"""

from __future__ import annotations

import argparse
import atexit
import os
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from pyshacl import validate as shacl_validate

from plugnproduce.description.datagraph import DataGraph
from plugnproduce.validation import validate as validation
from plugnproduce.validation.findings import Finding
from plugnproduce.validation.shapes import shape_problems, shapes_graph

DESCRIPTIONS = Path(__file__).resolve().parents[1] / "descriptions"


def plain(kg: DataGraph) -> list[Finding]:
    """The shapes run as pySHACL runs them unaided; the problems read off as :func:`shape_problems` reads them."""
    captured: list[object] = []
    real = shacl_validate

    def unaided(_data: object, **options: object) -> object:
        options.pop("inplace", None)
        captured.append(real(kg.graph, **options))  # type: ignore[arg-type]
        return captured[-1]

    import plugnproduce.validation.shapes as shapes

    shapes.shacl_validate = unaided  # type: ignore[assignment]
    try:
        return shape_problems(kg)
    finally:
        shapes.shacl_validate = real


def graph_of(paths: list[Path]) -> DataGraph:
    """The data graph ``pnp validate PATHS`` checks."""
    seen: list[DataGraph] = []
    real = validation.shape_problems

    def keep(kg: DataGraph) -> list[Finding]:
        seen.append(kg)
        return []

    validation.shape_problems = keep  # type: ignore[assignment]
    try:
        validation.validate_paths(paths)
    finally:
        validation.shape_problems = real
    return seen[0]


def _best(rounds: int, work: Callable[[], object]) -> float:
    work()
    times = []
    for _ in range(rounds):
        start = time.process_time()
        work()
        times.append(time.process_time() - start)
    return min(times)


BAD_STEPS = ("  - command: place\n    params:\n      place_pose: [0.6, -0.2, 0.1, 0, 180, 0]\n      speed: 9999\n"
             "  - command: pick\n    params:\n      grip_force: strong\n")


def main(rounds: int) -> None:
    shapes_graph()
    with tempfile.TemporaryDirectory() as folder:
        bad = Path(folder) / "bad-values.yaml"
        bad.write_text("task: bad-values\nsteps:\n" + BAD_STEPS * 20, encoding="utf-8")
        for label, paths in (("one task (pick-and-place.yaml)", [DESCRIPTIONS / "tasks" / "pick-and-place.yaml"]),
                             ("a 40-step task with 40 bad values", [bad]),
                             ("every built-in description", [DESCRIPTIONS])):
            kg = graph_of(paths)
            found = shape_problems(kg)
            assert found == plain(kg), "the two runs disagree"
            ours, theirs = _best(rounds, lambda g=kg: shape_problems(g)), _best(rounds, lambda g=kg: plain(g))
            print(f"{label}: {len(kg.graph):,} triples, {len(found)} problems; shapes {ours * 1000:.0f} ms, "
                  f"pySHACL unaided {theirs * 1000:.0f} ms ({theirs / ours:.1f}x); same problems")


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0] if __doc__ else None)
    parser.add_argument("--rounds", type=int, default=5)
    main(parser.parse_args().rounds)
