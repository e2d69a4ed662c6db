"""``pnp validate``: read every description under the given paths and check it."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import replace
from pathlib import Path

import rdflib
from rdflib.namespace import OWL, RDF

from plugnproduce.description.charts import device_chart
from plugnproduce.description.datagraph import DataGraph
from plugnproduce.description.goalfile import Goal, check_terms, load_goal
from plugnproduce.description.loader import (
    ContractError,
    Loaded,
    cell_device_files,
    cell_libraries,
    device_from,
    device_subject,
    file_of,
    load_task,
    not_a_description,
    process_from,
    read_description,
)
from plugnproduce.description.model import ProcessDescription, Task, Where
from plugnproduce.errors import DescriptionError, UnreadableError, excerpt
from plugnproduce.knowledge import Knowledge, Library, library_folders, load_knowledge
from plugnproduce.ontology.sources import read_tbox_file
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP, local_name
from plugnproduce.resources import ontology_path
from plugnproduce.safeio import read_bytes
from plugnproduce.statechart.io.reader import read_chart
from plugnproduce.statechart.io.schema import schema_problems
from plugnproduce.validation.findings import Finding, Report
from plugnproduce.validation.names import chart_name_problems, turtle_name_problems
from plugnproduce.validation.shapes import shape_problems
from plugnproduce.validation.structure import device_problems, process_problems, task_problems

XML_TBOX = {".owl", ".rdf", ".owx"}
"""TBox files as Protégé saves them (RDF/XML, OWL/XML): read, and classified with the knowledge."""
SUFFIXES = {".ttl", ".scxml", ".yaml", ".yml", *XML_TBOX}


def expand(paths: Iterable[str | Path]) -> list[Path]:
    """Files named, and the description files under folders named, sorted and without repeats."""
    out: set[Path] = set()
    for p in map(Path, paths):
        if p.is_dir():
            out |= {f for f in p.rglob("*") if f.suffix in SUFFIXES and f.is_file()}
        else:
            out.add(p)
    return sorted(out)


def validate_paths(paths: Iterable[str | Path], knowledge: Knowledge | None = None,
                   progress: Callable[[str], None] | None = None) -> Report:
    """Validate every description under ``paths`` against the schema, shapes and structure rules.

    ``knowledge`` gives the ontology and the known processes (default: the built-in library);
    TBox files among ``paths`` (``owl:Ontology`` documents, or files in an ``ontology/`` folder)
    are classified together with it. ``progress`` is told each phase as it begins.
    """
    say = progress or (lambda _: None)
    files = expand(paths)
    say(f"reading {len(files)} description file(s)")
    report = Report(files=[str(f) for f in files])
    knowledge = _with_extensions(knowledge or load_knowledge(), files, report)
    taxonomy = knowledge.taxonomy
    kg = DataGraph()
    kg.add_tbox(knowledge.tbox(), taxonomy)
    processes: dict[str, ProcessDescription] = {}
    tasks = []
    goals: list[Goal] = []
    described: dict[str, Where] = {}
    named: set[tuple[str, int]] = set()  # where a chart's unknown name is reported already
    for f in files:
        try:
            if not f.is_file():
                report.add(Finding(str(f), 0, "no such file", unreadable=True))
            elif f.suffix.lower() in XML_TBOX:
                read_tbox_file(f)  # read (and refused if hostile or malformed); classified with the knowledge
            elif f.suffix == ".scxml":
                for e in schema_problems(read_bytes(f), f):
                    report.add(Finding.from_error(e))
                for problem in chart_name_problems(f, taxonomy):
                    report.add(problem)
                    named.add((str(f.resolve()), problem.line))
            elif f.suffix == ".ttl":
                loaded = read_description(f)
                _same_iri(loaded, described, report)
                _turtle(loaded, taxonomy, kg, processes, report)
            elif _yaml_kind(f) == "task":
                tasks.append(load_task(f))
            elif _yaml_kind(f) == "goal":
                goals.append(load_goal(f))
            else:
                _cell(f, report, knowledge)
        except DescriptionError as exc:
            report.add(Finding.from_error(exc))
    _tasks(tasks, knowledge, processes, kg, report)
    for goal in goals:  # after the loop: the processes the files define are known then
        try:
            check_terms(goal, taxonomy, {p.id: p for p in knowledge.processes} | processes)
        except DescriptionError as exc:
            report.add(Finding.from_error(exc))
    if not report.unreadable:
        say("checking the SHACL shapes")
        for p in shape_problems(kg):
            if (_resolved(p.file), p.line) not in named or "is annotated with" not in p.message:
                report.add(p)
    return _once(report, files)


def _resolved(file: str) -> str:
    return str(Path(file).resolve()) if file and not file.startswith("<") else file


def _once(report: Report, files: list[Path]) -> Report:
    """Each problem once, at its file as the user named it (a chart a description names is read by
    its resolved path)."""
    given = {str(f.resolve()): str(f) for f in files}
    once = Report(files=report.files)
    for p in report.problems:
        once.add(replace(p, file=given.get(_resolved(p.file), p.file)))
    return once


def validate_tasks(tasks: Iterable[Task], knowledge: Knowledge | None = None) -> Report:
    """Validate tasks already read (from text, say) as :func:`validate_paths` validates task files:
    structure and SHACL shapes, each problem at its task's ``file`` and line."""
    tasks = list(tasks)
    knowledge = knowledge or load_knowledge()
    report = Report(files=[t.file for t in tasks])
    kg = DataGraph()
    kg.add_tbox(knowledge.tbox(), knowledge.taxonomy)
    _tasks(tasks, knowledge, {}, kg, report)
    for p in shape_problems(kg):
        report.add(p)
    return report


def _with_extensions(knowledge: Knowledge, files: list[Path], report: Report) -> Knowledge:
    """The knowledge with the TBox files among ``files`` and those of the libraries the files sit in."""
    known = set(knowledge.ontology_files())
    extra = {f.resolve() for f in files if f not in known and f.is_file()
             and (f.suffix.lower() in XML_TBOX or (f.suffix == ".ttl" and _is_tbox(f)))}
    builtin = ontology_path().resolve()
    for root in {p.resolve() for f in files for p in f.resolve().parents[:3] if (p / "ontology").is_dir()}:
        if (root / "ontology").resolve() == builtin:
            continue
        try:
            extra |= {t for t in Library(root).files("ontology") if t not in known}
        except DescriptionError as exc:  # a malformed file or an unresolved import: a finding at its line
            report.add(Finding.from_error(exc))
    if not extra:
        return knowledge
    try:
        return load_knowledge(knowledge.libraries, extra_tbox=sorted(extra), left_out=knowledge.left_out)
    except DescriptionError as exc:
        report.add(Finding.from_error(exc))
        return knowledge


def _is_tbox(path: Path) -> bool:
    if path.parent.name == "ontology":
        return path.name != "shapes.ttl"
    head = read_bytes(path)[:8192]
    return b"owl:Ontology" in head or b"2002/07/owl#Ontology" in head


def _same_iri(loaded: Loaded, described: dict[str, Where], report: Report) -> None:
    """Two files describing the same IRI (a device, process, role, parameter or class) are refused."""
    for s in sorted({str(s) for s in loaded.graph.subjects(RDF.type) if isinstance(s, rdflib.URIRef)}):
        first = described.setdefault(s, loaded.where(s))
        if first.file != str(loaded.path):
            report.add(Finding(str(loaded.path), loaded.line(s) or 0,
                               f"{local_name(s)} ({s}) is already described at {first}; "
                               "each IRI may be described by one file only"))


def _tasks(tasks: list[Task], knowledge: Knowledge, processes: dict[str, ProcessDescription], kg: DataGraph,
           report: Report) -> None:
    if not tasks:
        return
    library = {p.id: p for p in knowledge.processes if p.id not in processes}
    known = library | processes
    for process in library.values():
        kg.add_description(read_description(process.where.file))
        kg.add_process(process)
    for task in tasks:
        for p in task_problems(task, known, knowledge.taxonomy):
            report.add(p)
        kg.add_task(task, known)


def _turtle(
    loaded: Loaded, taxonomy: Taxonomy, kg: DataGraph, processes: dict[str, ProcessDescription], report: Report
) -> None:
    g = loaded.graph
    if (None, RDF.type, OWL.Ontology) in g or loaded.path.name == "shapes.ttl":
        return  # the ontology itself: parsed (so syntax is checked) and reasoned over already
    kg.add_description(loaded)
    for problem in turtle_name_problems(loaded, taxonomy):
        report.add(problem)
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
        lifted = device_chart(read_chart(file_of(chart)), file_of(chart)) if chart is not None else None
        states = (*lifted.states, *lifted.compounds) if lifted is not None else ()
        classes = [str(c) for c in g.objects(subject, RDF.type)]
        skills = taxonomy.device_skills(classes, [str(k) for k in g.objects(subject, PNP.hasSkill)])
        kg.add_device_facts(str(subject), skills, str(file_of(chart)) if chart is not None else "", states)
        try:
            device = device_from(loaded, taxonomy)
        except ContractError as exc:  # no shape can see a chart: a finding of its own
            report.add(Finding(str(exc.file), exc.line or 0, exc.message))
            return
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
        if line.startswith("goal:"):
            return "goal"
    return "task"


def _cell(path: Path, report: Report, knowledge: Knowledge) -> None:
    _, files = cell_device_files(path)
    knowledge = knowledge.with_libraries(library_folders(cell_libraries(path)))
    for f, line in files:
        if (why := not_a_description(f)) is not None:
            report.add(Finding(str(path), line, why))
        elif not f.is_file() and (f.suffix == ".ttl" or knowledge.device(f.name) is None):
            report.add(Finding(str(path), line, f"device description {excerpt(str(f), 120)} not found"))
