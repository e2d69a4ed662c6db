"""Benchmarks of the reasoner (prints figures; not a test).

    python bench/bench_reasoning.py [--configs 10000] [--owl-sample 5] [--seed 1]

1. offered commands of the bin-picking cell, warm (target < 20 ms);
2. batch feasibility of random configurations from the catalogue (target >= 5,000 configurations/s),
   against all processes, then also against the three built-in tasks;
3. the same question the plain OWL way: HermiT classification via owlready2 per configuration,
   on a small sample; reported as the ratio to the batch's time per configuration (target >= 1,000x);
4. the optimal repair of a 200-step task with 10 faults (target < 2 s).
"""

from __future__ import annotations

import argparse
import atexit
import io
import os
import random
import resource
import statistics
import tempfile
import time
from dataclasses import replace

import rdflib
from rdflib.namespace import OWL, RDF

from plugnproduce import service
from plugnproduce.batch import Configuration
from plugnproduce.description.model import Step, Task
from plugnproduce.ontology.taxonomy import ontology_files, read_tbox

PNP = rdflib.Namespace("http://plugnproduce.org/ontology#")
BENCH = rdflib.Namespace("http://plugnproduce.org/bench#")


def cpu() -> float:
    """CPU seconds (user+sys) of this process and of its children waited for (batch workers, the reasoner's JVM)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def bench_offered(runs: int = 200) -> None:
    """Warm time of capabilities() on the bin-picking cell."""
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    service.capabilities(cell)
    times, cpus = [], []
    for _ in range(runs):
        t, c = time.perf_counter(), cpu()
        service.capabilities(cell)
        cpus.append(cpu() - c)
        times.append(time.perf_counter() - t)
    print(f"offered commands, bin-picking cell (warm): median {1000 * statistics.median(times):.2f} ms, "
          f"p95 {1000 * sorted(times)[int(0.95 * runs)]:.2f} ms, CPU median {1000 * statistics.median(cpus):.2f} ms "
          f"over {runs} runs (target < 20 ms)")


def bench_batch(count: int, seed: int) -> tuple[float, float]:
    """Throughput of batch(); returns the seconds and the CPU seconds per configuration of the processes-only
    run."""
    configs = list(service.generate_configurations(count, (2, 6), seed))
    distinct = len({frozenset(c.devices) for c in configs})
    tasks = [service.task(service.builtin("tasks", f"{n}.yaml"))
             for n in ("bin-picking", "bin-picking-invalid", "pick-and-place")]
    per_config = per_config_cpu = 0.0
    for label, given in (("all processes", []), ("all processes + 3 tasks", tasks)):
        t, c = time.perf_counter(), cpu()
        rows = list(service.batch(configs, tasks=given, workers=2))
        dt, dc = time.perf_counter() - t, max(cpu() - c, 1e-9)
        per_config = per_config or dt / len(rows)
        per_config_cpu = per_config_cpu or dc / len(rows)
        print(f"batch, {label}: {len(rows)} configurations ({distinct} distinct device sets) in {dt:.2f} s = "
              f"{len(rows) / dt:,.0f} configurations/s, {distinct / dt:,.0f} distinct sets/s (target >= 5,000/s); "
              f"CPU {dc:.2f} s = {len(rows) / dc:,.0f} configurations per CPU second")
    return per_config, per_config_cpu


def owl_offered(config: Configuration, tbox: rdflib.Graph) -> set[str]:
    """Offered processes of one configuration by HermiT: the cell is an instance of Offered_P when, for
    every role of P, some member has a skill the role's skill subsumes (skills only: OWL has no chart order)."""
    import owlready2

    k = service.knowledge()
    devices = {d.id: d for d in service.catalogue()}
    g = rdflib.Graph() + tbox
    cell = BENCH["cell"]
    g.add((BENCH.hasMember, RDF.type, OWL.ObjectProperty))
    for d in config.devices:
        ind = BENCH[d]
        g.add((cell, BENCH.hasMember, ind))
        for c in devices[d].classes:
            g.add((ind, RDF.type, rdflib.URIRef(c)))
        for s in devices[d].declared_skills:  # a skill individual typed by the skill class
            skill = BENCH[f"{d}-{s.rsplit('#', 1)[-1]}"]
            g.add((skill, RDF.type, rdflib.URIRef(s)))
            g.add((ind, PNP.hasSkill, skill))
    for p in k.processes:
        _offered_class(g, p.id, [r.required_skill for r in p.roles])
    nt = g.serialize(format="nt", encoding="utf-8")
    world = owlready2.World()
    onto = world.get_ontology("http://plugnproduce.org/ontology").load(fileobj=io.BytesIO(nt), format="ntriples")
    with tempfile.TemporaryDirectory(prefix="pnp-bench-") as tmp:
        saved, tempfile.tempdir = tempfile.tempdir, tmp
        try:
            with onto:
                owlready2.sync_reasoner_hermit(world, infer_property_values=False, debug=0)
        finally:
            tempfile.tempdir = saved
    ind = world[str(cell)]
    return {c.iri.rsplit("Offered_", 1)[1] for c in ind.INDIRECT_is_a if "Offered_" in getattr(c, "iri", "")}


def _offered_class(g: rdflib.Graph, process: str, skills: list[str]) -> None:
    parts = []
    for s in skills:
        has = rdflib.BNode()
        g.add((has, RDF.type, OWL.Restriction))
        g.add((has, OWL.onProperty, PNP.hasSkill))
        g.add((has, OWL.someValuesFrom, rdflib.URIRef(s)))
        member = rdflib.BNode()
        g.add((member, RDF.type, OWL.Restriction))
        g.add((member, OWL.onProperty, BENCH.hasMember))
        g.add((member, OWL.someValuesFrom, has))
        parts.append(member)
    offered, both, lst = BENCH[f"Offered_{process}"], rdflib.BNode(), rdflib.BNode()
    rdflib.collection.Collection(g, lst, parts)
    g.add((offered, RDF.type, OWL.Class))
    g.add((both, RDF.type, OWL.Class))
    g.add((both, OWL.intersectionOf, lst))
    g.add((offered, OWL.equivalentClass, both))


def bench_owl(sample: int, seed: int, asp_per_config: tuple[float, float]) -> None:
    """HermiT per configuration on a sample, against the batch's time per configuration."""
    configs = list(service.generate_configurations(sample, (2, 6), seed + 1))
    tbox = read_tbox(ontology_files())
    asp = {r.config: set(r.offered) for r in service.batch(configs, workers=1)}
    times, cpus, agree = [], [], 0
    for c in configs:
        t, started = time.perf_counter(), cpu()
        owl = owl_offered(c, tbox)
        cpus.append(cpu() - started)
        times.append(time.perf_counter() - t)
        agree += owl == asp[c.name]
    per, per_cpu = statistics.mean(times), statistics.mean(cpus)
    print(f"plain OWL (HermiT per configuration, {sample} configurations): {per:.2f} s each (CPU {per_cpu:.2f} s); "
          f"ratio to the batch {per / asp_per_config[0]:,.0f}x, CPU {per_cpu / asp_per_config[1]:,.0f}x "
          "(target >= 1,000x); "
          f"same offered set as ASP for {agree}/{sample} (OWL checks skills only)")


def faulty_task(pairs: int, faults: int, seed: int) -> Task:
    """(bin-pick, place) x pairs with faults: a place became move-to, a place swapped with the next bin-pick,
    a grip force out of range, a robot bound to a device not in the cell."""
    rnd = random.Random(seed)
    steps = [Step(0, c) for _ in range(pairs) for c in ("bin-pick", "place")]
    for n, pair in enumerate(sorted(rnd.sample(range(1, pairs - 1), faults))):
        i = 2 * pair + 1  # a place
        kind = "ABCD"[n % 4]
        if kind == "A":
            steps[i] = Step(0, "move-to")
        elif kind == "B":
            steps[i], steps[i + 1] = steps[i + 1], steps[i]
        elif kind == "C":
            steps[i - 1] = replace(steps[i - 1], params={"grip_force": 500})
        else:
            steps[i] = replace(steps[i], bind={"robot": "scara"})
    return Task("bench", tuple(replace(s, index=n) for n, s in enumerate(steps, start=1)), "bench.yaml")


def bench_repair(seed: int) -> None:
    """Optimal repair (top 1, then top 3) of a 200-step task with 10 faults."""
    cell = service.cell(service.builtin("cells", "bin-picking.yaml"))
    task = faulty_task(100, 10, seed)
    problems = len(service.check(task, cell).problems)
    for top, catalogue in ((1, None), (3, None), (1, service.catalogue())):
        t, c = time.perf_counter(), cpu()
        repairs = service.repair(task, cell, catalogue, top=top)
        dt, dc = time.perf_counter() - t, cpu() - c
        best = repairs[0]
        kinds = sorted({e.kind for e in best.edits})
        what = f"top {top}" + (", built-in catalogue" if catalogue else "")
        print(f"repair, 200 steps, 10 faults ({problems} problems), {what}: {dt:.2f} s (CPU {dc:.2f} s); "
              f"optimal cost {best.cost:g}"
              f" with {len(best.edits)} edits ({', '.join(kinds)}); plausible after: "
              f"{service.check(best.task, cell).plausible} (target < 2 s)")


def main() -> None:
    """Run every benchmark and print its figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--configs", type=int, default=10000)
    parser.add_argument("--owl-sample", type=int, default=5)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    bench_offered()
    per_config = bench_batch(args.configs, args.seed)
    bench_owl(args.owl_sample, args.seed, per_config)
    bench_repair(args.seed)


if __name__ == "__main__":
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores at the start", flush=True)
    atexit.register(lambda: print(f"load average {os.getloadavg()[0]:.2f} at the end"))
    main()
