"""``pnp validate``: read every description under the given paths and check it."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from rdflib.namespace import OWL, RDF

from plugnproduce.description.charts import device_chart
from plugnproduce.description.knowledge import KnowledgeGraph
from plugnproduce.description.loader import (
    Loaded,
    cell_device_files,
    device_from,
    device_subject,
    file_of,
    load_task,
    process_from,
    read_description,
)
from plugnproduce.description.model import ProcessDescription
from plugnproduce.errors import DescriptionError, UnreadableError
from plugnproduce.ontology.taxonomy import Taxonomy, load_taxonomy, ontology_files, read_tbox
from plugnproduce.ontology.vocabulary import PNP
from plugnproduce.resources import descriptions_path
from plugnproduce.safeio import excerpt, read_bytes
from plugnproduce.statechart.schema import schema_problems
from plugnproduce.validation.findings import Problem, Report
from plugnproduce.validation.shapes import shape_problems
from plugnproduce.validation.structure import device_problems, process_problems, task_problems

SUFFIXES = {".ttl", ".scxml", ".yaml", ".yml"}


def expand(paths: Iterable[str | Path]) -> list[Path]:
    """Files named, and the description files under folders named, sorted and without repeats."""
    out: set[Path] = set()
    for p in map(Path, paths):
        if p.is_dir():
            out |= {f for f in p.rglob("*") if f.suffix in SUFFIXES and f.is_file()}
        else:
            out.add(p)
    return sorted(out)


def validate_paths(
    paths: Iterable[str | Path], taxonomy: Taxonomy | None = None, ontology: list[Path] | None = None
) -> Report:
    """Validate every description under ``paths`` against the schema, shapes and structure rules.

    ``ontology`` names the TBox files (default: the built-in ontology); ``taxonomy`` is their
    closure if the caller has it already.
    """
    files = expand(paths)
    report = Report(files=[str(f) for f in files])
    tbox_files = ontology or ontology_files()
    taxonomy = taxonomy or load_taxonomy(tbox_files)
    kg = KnowledgeGraph()
    kg.add_tbox(read_tbox(tbox_files), taxonomy)
    processes: dict[str, ProcessDescription] = {}
    tasks = []
    known: dict[str, ProcessDescription] = {}
    for f in files:
        try:
            if not f.is_file():
                report.add(Problem(str(f), 0, "no such file", unreadable=True))
            elif f.suffix == ".scxml":
                for e in schema_problems(read_bytes(f), f):
                    report.add(Problem.from_error(e))
            elif f.suffix == ".ttl":
                _turtle(read_description(f), taxonomy, kg, processes, report)
            elif _yaml_kind(f) == "task":
                tasks.append(load_task(f))
            else:
                _cell(f, report)
        except DescriptionError as exc:
            report.add(Problem.from_error(exc))
    if tasks:
        builtin = {p.id: (loaded, p) for loaded, p in _builtin_processes() if p.id not in processes}
        known = {k: p for k, (_, p) in builtin.items()} | processes
        for loaded, process in builtin.values():
            kg.add_description(loaded)
            kg.add_process(process)
    for task in tasks:
        for p in task_problems(task, known):
            report.add(p)
        kg.add_task(task, known)
    if not report.unreadable:
        for p in shape_problems(kg):
            report.add(p)
    return report


def _turtle(
    loaded: Loaded, taxonomy: Taxonomy, kg: KnowledgeGraph, processes: dict[str, ProcessDescription], report: Report
) -> None:
    g = loaded.graph
    if (None, RDF.type, OWL.Ontology) in g or loaded.path.name == "shapes.ttl":
        return  # the ontology itself: parsed (so syntax is checked) and reasoned over already
    kg.add_description(loaded)
    if (None, PNP.generalChart, None) in g:
        process = process_from(loaded)
        processes[process.id] = process
        kg.add_process(process)
        for p in process_problems(process, taxonomy):
            report.add(p)
    else:
        # Lift what there is even when metadata is missing (the shapes report that); only a
        # complete device gets the structure checks.
        subject = device_subject(loaded, taxonomy)
        chart = g.value(subject, PNP.stateChart)
        states = device_chart(file_of(chart))[1] if chart is not None else ()
        classes = [str(c) for c in g.objects(subject, RDF.type)]
        skills = taxonomy.device_skills(classes, [str(k) for k in g.objects(subject, PNP.hasSkill)])
        kg.add_device_facts(str(subject), skills, str(file_of(chart)) if chart is not None else "", states)
        try:
            device = device_from(loaded, taxonomy)
        except DescriptionError as exc:
            if isinstance(exc, UnreadableError):
                raise
            return
        for p in device_problems(device):
            report.add(p)


def _yaml_kind(path: Path) -> str:
    head = read_bytes(path)[:4096].decode("utf-8", "replace")
    for line in head.splitlines():
        if line.startswith("task:"):
            return "task"
        if line.startswith("cell:"):
            return "cell"
    return "task"


def _cell(path: Path, report: Report) -> None:
    _, files = cell_device_files(path)
    for f, line in files:
        if not f.is_file():
            report.add(Problem(str(path), line, f"device description {excerpt(str(f), 120)} not found"))


def _builtin_processes() -> list[tuple[Loaded, ProcessDescription]]:
    out = []
    for f in sorted((descriptions_path() / "processes").glob("*.ttl")):
        loaded = read_description(f)
        out.append((loaded, process_from(loaded)))
    return out
