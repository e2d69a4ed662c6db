"""The use cases behind every interface (CLI, HTTP API, notebooks).

Functions here load descriptions, call the concepts (validation, reasoning, code
generation, execution) and return typed results; they never print.
"""

from __future__ import annotations

import asyncio
import contextlib
import dataclasses
import secrets
import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, TypedDict

from plugnproduce import folders
from plugnproduce.description.loader import (
    cell_libraries,
    load_cell,
    load_devices,
    load_task,
    parse_task,
    task_to_yaml,
)
from plugnproduce.description.model import Cell, DeviceDescription, Link, Task
from plugnproduce.errors import PlugNProduceError
from plugnproduce.knowledge import Knowledge, Library, builtin_library, library_folders, load_knowledge
from plugnproduce.lazy import lazy_module
from plugnproduce.resources import descriptions_path

if TYPE_CHECKING:  # validation, code generation and execution are imported by the use cases that need them
    from plugnproduce import reasoning
    from plugnproduce.codegen import GeneratedTask
    from plugnproduce.codegen.outputs import GeneratedChart
    from plugnproduce.description.goalfile import Goal
    from plugnproduce.discovery import LiveCell
    from plugnproduce.executor.history import RunSummary
    from plugnproduce.executor.journal import RunRecord
    from plugnproduce.executor.report import RunReport
    from plugnproduce.executor.run import RecordObserver, TaskRun
    from plugnproduce.ontology.taxonomy import Taxonomy
    from plugnproduce.planning import Plan, Unreachable
    from plugnproduce.reasoning.impact import Impact
    from plugnproduce.validation import Report
    from plugnproduce.verification import Budget, Verification
else:
    reasoning = lazy_module("plugnproduce.reasoning")  # a validation needs no reasoner


@lru_cache(maxsize=8)
def _loaded(libraries: tuple[Library, ...]) -> Knowledge:
    return load_knowledge(libraries)


def knowledge(libraries: tuple[str | Path, ...] = (), builtin: bool = True) -> Knowledge:
    """Load the knowledge of the built-in library (unless ``builtin`` is false) and ``libraries``.

    Loading the same libraries again returns the same object; every use case takes the result as
    its ``knowledge`` argument (default: the built-in library alone).
    """
    libs = ((builtin_library(),) if builtin else ()) + library_folders(libraries)
    return _loaded(libs)


def knowledge_for_cell(path: str | Path, base: Knowledge | None = None) -> Knowledge:
    """``base`` (default: built-in) with the libraries a cell file lists under ``libraries:``."""
    base = base or knowledge()
    return base.with_libraries(library_folders(cell_libraries(path)))


def _k(k: Knowledge | None) -> Knowledge:
    return k if k is not None else knowledge()


def validate(paths: list[str | Path], knowledge: Knowledge | None = None,
             progress: Callable[[str], None] | None = None) -> Report:
    """Validate description files and folders; ``progress`` is told each phase as it begins."""
    from plugnproduce.validation import validate_paths

    return validate_paths(paths, _k(knowledge), progress=progress)


def validate_tasks(tasks: list[Task], knowledge: Knowledge | None = None) -> Report:
    """Validate tasks already read (e.g. from an editor's YAML) as :func:`validate` validates task files."""
    from plugnproduce.validation import validate_tasks as validate_read

    return validate_read(tasks, _k(knowledge))


def cell(path: str | Path, knowledge: Knowledge | None = None) -> Cell:
    """Read a cell file (with the libraries it lists, added to ``knowledge``)."""
    k = knowledge_for_cell(path, knowledge)
    return load_cell(path, k.taxonomy, k.device)


def catalogue(folder: str | Path | None = None, knowledge: Knowledge | None = None) -> list[DeviceDescription]:
    """Read a catalogue of device descriptions (default: every device of the loaded libraries)."""
    k = _k(knowledge)
    return list(k.devices) if folder is None else load_devices(folder, k.taxonomy)


def task(path: str | Path) -> Task:
    """Read a task file."""
    return load_task(path)


def task_from_text(data: bytes | str, name: str) -> Task:
    """Read a task description from YAML text (an upload, an editor's buffer); ``name`` names it in messages."""
    return parse_task(data.encode("utf-8") if isinstance(data, str) else data, name)


def task_text(the_task: Task, block: bool = False) -> str:
    """A task as a YAML task file (``block``: every value on a line of its own)."""
    return task_to_yaml(the_task, block)


def builtin(*parts: str) -> Path:
    """A path inside the built-in descriptions, e.g. ``builtin("cells", "bin-picking.yaml")``."""
    return descriptions_path().joinpath(*parts)



class DeviceView(TypedDict):
    """A device as every face shows it (``pnp discover --json``, the HTTP API, the page)."""

    id: str
    label: str
    classes: list[str]
    """The labels of its classes in the taxonomy."""
    skills: list[str]
    """The labels of its skills."""
    protocol: str
    endpoint: str


def device_view(device: DeviceDescription, taxonomy: Taxonomy) -> DeviceView:
    """The one JSON view of a device both faces give: id, label, classes, skills, protocol, endpoint."""
    return {"id": device.id, "label": device.label,
            "classes": [taxonomy.label(c) for c in device.classes],
            "skills": [taxonomy.label(s) for s in device.skills],
            "protocol": device.protocol, "endpoint": device.endpoint}


CellArg = Cell | str | Path
TaskArg = Task | str | Path


def _context(cell_or_path: CellArg, knowledge: Knowledge | None) -> tuple[Cell, Knowledge]:
    """The cell and the knowledge to reason with: ``knowledge`` plus the cell file's libraries."""
    if isinstance(cell_or_path, Cell):
        if cell_or_path.file and Path(cell_or_path.file).is_file():
            return cell_or_path, knowledge_for_cell(cell_or_path.file, knowledge)
        return cell_or_path, _k(knowledge)
    k = knowledge_for_cell(cell_or_path, knowledge)
    return load_cell(cell_or_path, k.taxonomy, k.device), k


def _as_task(task_or_path: TaskArg) -> Task:
    return task_or_path if isinstance(task_or_path, Task) else task(task_or_path)


def _devices(catalogue_or_folder: list[DeviceDescription] | str | Path | None, k: Knowledge) -> list[DeviceDescription]:
    if isinstance(catalogue_or_folder, list):
        return catalogue_or_folder
    return catalogue(catalogue_or_folder, k)


def capabilities(cell_or_path: CellArg, knowledge: Knowledge | None = None,
                 all_bindings: bool = False) -> reasoning.Capabilities:
    """The process commands a cell offers, each with one valid role binding, how many there are and the
    devices that can fill each role (every binding listed if ``all_bindings``); the others with reasons."""
    the_cell, k = _context(cell_or_path, knowledge)
    return reasoning.capabilities(the_cell, k.taxonomy, k.processes, all_bindings)


def check(task_or_path: TaskArg, cell_or_path: CellArg, knowledge: Knowledge | None = None) -> reasoning.CheckResult:
    """Whether a task is plausible in a cell: per step its bindings, device states and problems."""
    from plugnproduce.reasoning.linksafety import link_safety

    the_cell, k = _context(cell_or_path, knowledge)
    task = _as_task(task_or_path)
    result = reasoning.check(task, the_cell, k.taxonomy, k.processes)
    return dataclasses.replace(result, links=link_safety(task, the_cell, result, k.processes))


def repair(
    task_or_path: TaskArg,
    cell_or_path: CellArg,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    top: int = 3,
    costs: reasoning.RepairCosts | None = None,
    knowledge: Knowledge | None = None,
) -> list[reasoning.Repair]:
    """The ``top`` cheapest distinct repairs of an implausible task (none if it is plausible).

    With a catalogue (device descriptions, or a folder of them) a repair may add a device.
    """
    the_cell, k = _context(cell_or_path, knowledge)
    devices = None if catalogue_or_folder is None else _devices(catalogue_or_folder, k)
    return reasoning.repair(_as_task(task_or_path), the_cell, k.taxonomy, k.processes,
                            catalogue=devices, top=top, costs=costs)


def plan(goal_or_path: Goal | str | Path, cell_or_path: CellArg, knowledge: Knowledge | None = None,
         catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
         source: str | None = None) -> Plan | Unreachable:
    """A task that reaches a goal in a cell, from its devices' states (a cell with reported states plans from
    those), or why none does, with the cheapest catalogue device (built-in and library) that would make one.
    ``source`` names the written task file."""
    from plugnproduce.description.goalfile import Goal, load_goal
    from plugnproduce.planning import plan as make_plan

    the_cell, k = _context(cell_or_path, knowledge)
    goal = goal_or_path if isinstance(goal_or_path, Goal) else load_goal(goal_or_path)
    devices = list(k.devices) if catalogue_or_folder is None else _devices(catalogue_or_folder, k)
    return make_plan(goal, the_cell, k.taxonomy, k.processes, devices, source=source)


def plan_pddl(goal_or_path: Goal | str | Path, cell_or_path: CellArg,
              knowledge: Knowledge | None = None) -> tuple[str, str]:
    """A goal without ``until`` as a PDDL domain and problem whose optimal plans cost what :func:`plan` optimises."""
    from plugnproduce.description.goalfile import Goal, load_goal
    from plugnproduce.planning.pddl import export

    the_cell, k = _context(cell_or_path, knowledge)
    return export(goal_or_path if isinstance(goal_or_path, Goal) else load_goal(goal_or_path), the_cell, k.taxonomy,
                  k.processes)


def catalogue_players(result: reasoning.CheckResult,
                      knowledge: Knowledge | None = None) -> dict[tuple[int, str], list[str]]:
    """For each step role no device of the cell can play: the catalogue devices (built-in and library) that could."""
    k = _k(knowledge)
    out: dict[tuple[int, str], list[str]] = {}
    for p in result.problems:
        if p.kind != "no_device" or p.role is None:
            continue
        needed = k.process(p.command).role(p.role).required_skill
        out[(p.step, p.role)] = [d.id for d in k.devices if any(k.taxonomy.is_a(s, needed) for s in d.skills)]
    return out


def explain_process(cell_or_path: CellArg, command: str,
                    knowledge: Knowledge | None = None) -> reasoning.ProcessExplanation:
    """Why a process command is (not) offered in a cell."""
    the_cell, k = _context(cell_or_path, knowledge)
    return reasoning.explain_process(the_cell, command, k.taxonomy, k.processes)


def explain_step(task_or_path: TaskArg, cell_or_path: CellArg, n: int,
                 knowledge: Knowledge | None = None) -> reasoning.StepExplanation:
    """Why step ``n`` (1-based) of a task is (not) plausible in a cell."""
    the_cell, k = _context(cell_or_path, knowledge)
    return reasoning.explain_step(_as_task(task_or_path), the_cell, n, k.taxonomy, k.processes)


def explain_offered(cell_or_path: CellArg, command: str, knowledge: Knowledge | None = None,
                    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
                    language: str = "en") -> reasoning.Explanation:
    """Why a process command is (not) offered: the derivation tree (rules, ontology axioms, chart states) and
    the counterfactuals the reasoner confirms (devices of the catalogue to add or swap in; for a "yes", the
    devices it rests on)."""
    the_cell, k = _context(cell_or_path, knowledge)
    ontology = reasoning.ontology_of(k.ontology_files(), k.taxonomy)
    return reasoning.explain_offered(command, the_cell, k.taxonomy, ontology, k.processes,
                                     _devices(catalogue_or_folder, k), language)


def explain_plausible(task_or_path: TaskArg, cell_or_path: CellArg, n: int, knowledge: Knowledge | None = None,
                      language: str = "en") -> reasoning.Explanation:
    """Why step ``n`` (1-based) of a task is (not) plausible: the derivation tree and, for a "no", the states its
    devices would have to be in and the repairs (steps to insert, remove or reorder, with their side effects),
    each confirmed by the reasoner."""
    the_cell, k = _context(cell_or_path, knowledge)
    the_task = _as_task(task_or_path)
    ontology = reasoning.ontology_of(k.ontology_files(), k.taxonomy)
    ex = reasoning.explain_plausible(the_task, n, the_cell, k.taxonomy, ontology, k.processes, language)
    if ex.answer:
        return ex
    edits = reasoning.counterfactuals_from_repairs(assessed_repairs(the_task, the_cell, None, 3, k))
    return dataclasses.replace(ex, counterfactuals=ex.counterfactuals + tuple(edits),
                               none_exists=None if ex.counterfactuals or edits else ex.none_exists)


MORE_REPAIRS = 3
"""How many times :func:`assessed_repairs` asks the solver (for ``top``, then ``2 top``, ... repairs) while the
check refuses some of them."""


def assessed_repairs(
    task_or_path: TaskArg,
    cell_or_path: CellArg,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    top: int = 3,
    knowledge: Knowledge | None = None,
    checked: reasoning.CheckResult | None = None,
) -> list[reasoning.AssessedRepair]:
    """The repairs of :func:`repair` that checking them again confirms, with their side effects, ranked by their
    worst side effect, then by cost (:func:`plugnproduce.reasoning.sideeffects.ranking`). When the check refuses
    some of the solver's repairs, the solver is asked for more, up to :data:`MORE_REPAIRS` rounds. ``checked``: the
    task's :func:`check` in that cell, when the caller has it (it is not checked again)."""
    the_cell, k = _context(cell_or_path, knowledge)
    the_task = _as_task(task_or_path)
    devices = None if catalogue_or_folder is None else _devices(catalogue_or_folder, k)
    asked = top
    for _ in range(MORE_REPAIRS):
        repairs = repair(the_task, the_cell, devices, asked, knowledge=k)
        assessed = reasoning.assess(repairs, the_task, the_cell, k.taxonomy, k.processes, devices or (), checked)
        if len(assessed) >= top or len(repairs) < asked:
            break
        asked += top
    return assessed[:top]


def batch(
    configurations: Iterable[reasoning.Configuration] | str | Path,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    tasks: list[Task | str | Path] | None = None,
    workers: int = 2,
    progress: Callable[[int], None] | None = None,
    knowledge: Knowledge | None = None,
    top: int = 1,
    cluster: str | reasoning.ClusterAccess | None = None,
) -> Iterator[reasoning.BatchRow]:
    """Feasibility of many configurations (an iterable, or a JSONL/CSV file of device lists) of catalogue
    devices, streamed in order: per configuration the offered processes, the plausible tasks, and when
    some task is not, the ``top`` cheapest sets of catalogue devices to add (or why none suffices).
    ``cluster``: a Dask scheduler address (``tcp://host:8786``) or ``local:N`` (N local worker processes), or a
    :class:`~plugnproduce.reasoning.ClusterAccess` with its connect timeout and TLS files; a cluster address is
    trusted code execution (it runs what the batch sends, and what comes back is unpickled)."""
    k = _k(knowledge)
    devices = _devices(catalogue_or_folder, k)
    configs = (reasoning.read_configurations(configurations) if isinstance(configurations, str | Path)
               else configurations)
    mapper = reasoning.cluster_mapper(cluster) if cluster is not None else None
    return reasoning.batch(configs, devices, [_as_task(t) for t in tasks or []], k.taxonomy, k.processes,
                           workers=workers, progress=progress, top=top, mapper=mapper)


def batch_report(
    configurations: Iterable[reasoning.Configuration] | str | Path,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    tasks: list[Task | str | Path] | None = None,
    form: str = "jsonl",
    workers: int = 2,
    progress: Callable[[int], None] | None = None,
    knowledge: Knowledge | None = None,
    top: int = 1,
    cluster: str | reasoning.ClusterAccess | None = None,
    tally: dict[str, int] | None = None,
) -> Iterator[str]:
    """:func:`batch`'s answers as report text (JSONL, or CSV rows with ``form`` "csv"), a chunk at a time,
    made by the workers: what ``pnp batch`` writes. ``tally`` counts the configurations written by outcome
    (all plausible, a purchase, a role to bind, nothing helps)."""
    k = _k(knowledge)
    devices = _devices(catalogue_or_folder, k)
    configs = (reasoning.read_configurations(configurations) if isinstance(configurations, str | Path)
               else configurations)
    mapper = reasoning.cluster_mapper(cluster) if cluster is not None else None
    return reasoning.report(configs, devices, [_as_task(t) for t in tasks or []], k.taxonomy, k.processes,
                            form=form, workers=workers, progress=progress, top=top, mapper=mapper, tally=tally)


def batch_engine(
    catalogue_folder: str | Path | None,
    tasks: list[str | Path],
    top: int = 1,
    libraries: tuple[str | Path, ...] = (),
    builtin: bool = True,
) -> reasoning.Engine:
    """What a batch over files reasons once (the catalogue devices and tasks against the libraries' processes),
    kept in the user's cache folder: a later batch over the same files, unchanged, reads it back instead of
    reading and reasoning over every description again (:mod:`.reasoning.enginecache`)."""
    from plugnproduce.reasoning import enginecache

    folder = Path(catalogue_folder) if catalogue_folder is not None else None
    libs = ((builtin_library(),) if builtin else ()) + library_folders(libraries)

    def build() -> reasoning.Engine:
        k = knowledge(libraries, builtin)
        return reasoning.engine(catalogue(folder, k), [task(p) for p in tasks], k.taxonomy, k.processes, top)

    key = enginecache.digest(libs, folder, [Path(p) for p in tasks], top)
    found = enginecache.cached(key, build)
    return found if isinstance(found, reasoning.Engine) else build()


def batch_report_from(
    engine: reasoning.Engine,
    configurations: Iterable[reasoning.Configuration] | str | Path,
    form: str = "jsonl",
    workers: int = 2,
    progress: Callable[[int], None] | None = None,
    cluster: str | reasoning.ClusterAccess | None = None,
    tally: dict[str, int] | None = None,
) -> Iterator[str]:
    """:func:`batch_report` by an engine already built (:func:`batch_engine`)."""
    configs = (reasoning.read_configurations(configurations) if isinstance(configurations, str | Path)
               else configurations)
    mapper = reasoning.cluster_mapper(cluster) if cluster is not None else None
    return reasoning.report_from(engine, configs, form=form, workers=workers, progress=progress, mapper=mapper,
                                 tally=tally)


def generate_configurations(
    count: int,
    sizes: tuple[int, int],
    seed: int,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    knowledge: Knowledge | None = None,
) -> Iterator[reasoning.Configuration]:
    """``count`` random configurations of ``sizes[0]``-``sizes[1]`` distinct catalogue devices, generated lazily."""
    return reasoning.generate(_devices(catalogue_or_folder, _k(knowledge)), count, sizes, seed)


# ------------------------------------------------------------------ code generation


class ImplausibleTask(PlugNProduceError):
    """A task the plausibility check refuses; ``result`` holds the problems per step."""

    def __init__(self, result: reasoning.CheckResult):
        self.result = result
        super().__init__(f"task {result.task} is not plausible in cell {result.cell}: "
                         + "; ".join(str(p) for p in result.problems))


@dataclass(frozen=True)
class Generated:
    """A task's generated program: the task chart model and every chart written for it."""

    task: GeneratedTask
    charts: list[GeneratedChart]
    verification: Verification | None = None
    """Every interleaving explored (when asked for); the charts are only for a proved program."""


@dataclass(frozen=True)
class Generation:
    """The plausibility check of a task and, when it is plausible (and proved, when verified), its generated
    program (else None), with the verification's answer when it was verified."""

    check: reasoning.CheckResult
    generated: Generated | None
    verification: Verification | None = None

    @property
    def charts(self) -> list[GeneratedChart]:
        """The charts written for the task (none for an implausible or unproved task)."""
        return self.generated.charts if self.generated is not None else []


def _generate_task(the_task: Task, the_cell: Cell, result: reasoning.CheckResult, k: Knowledge) -> GeneratedTask:
    from plugnproduce.codegen import generate_task

    in_units, _ = reasoning.normalised(the_task, k.processes)  # the values in their parameters' units
    return generate_task(in_units, the_cell, result.bindings(), {p.id: p for p in k.processes}, k.taxonomy)


def generation(task_or_path: TaskArg, cell_or_path: CellArg, per_device: bool = False,
               knowledge: Knowledge | None = None, verify: Budget | None = None) -> Generation:
    """Check a task and, when it is plausible, generate its specific process charts, task chart,
    closed-world chart and, with ``per_device``, each device's program.

    With a ``verify`` budget every interleaving of the program is explored first (:func:`verify`)
    and charts are made only for a proved program. An implausible or unproved task is a result
    here (``generated`` is None), not an error.
    """
    the_task, (the_cell, k) = _as_task(task_or_path), _context(cell_or_path, knowledge)
    result = check(the_task, the_cell, k)
    if not result.plausible:
        return Generation(result, None)
    from plugnproduce.codegen.outputs import all_charts

    generated = _generate_task(the_task, the_cell, result, k)
    proof = _verify(generated, the_cell, verify) if verify is not None else None
    if proof is not None and not proof.proved:
        return Generation(result, None, proof)
    return Generation(result, Generated(generated, all_charts(generated, the_cell, per_device), proof), proof)


def generate(task_or_path: TaskArg, cell_or_path: CellArg, per_device: bool = False,
             knowledge: Knowledge | None = None, verify: Budget | None = None) -> Generated:
    """:func:`generation` for a task that must be plausible (else :class:`ImplausibleTask`) and, with a
    ``verify`` budget, proved (else :class:`Unverified`, and no charts are made)."""
    result = generation(task_or_path, cell_or_path, per_device, knowledge, verify)
    if result.generated is not None:
        return result.generated
    if result.verification is not None:
        raise Unverified(result.verification)
    raise ImplausibleTask(result.check)


class Unverified(PlugNProduceError):
    """A generated program that verification refuted, or could not prove within its budget."""

    def __init__(self, verification: Verification):
        self.verification = verification
        super().__init__("; ".join(verification.lines()[:2]))


def verify(task_or_path: TaskArg, cell_or_path: CellArg, budget: Budget | None = None,
           knowledge: Knowledge | None = None) -> Verification:
    """Check and generate a task, then explore every interleaving of its program with the cell's device
    charts within ``budget``: proved, refuted (with the shortest counterexample) or inconclusive.
    Raises :class:`ImplausibleTask` for an implausible task."""
    the_task, (the_cell, k) = _as_task(task_or_path), _context(cell_or_path, knowledge)
    return _verify(plan_run(the_task, the_cell, k), the_cell, budget)


def _verify(generated: GeneratedTask, the_cell: Cell, budget: Budget | None) -> Verification:
    from plugnproduce.verification import verify as explore

    return explore(generated, the_cell, budget)


# ------------------------------------------------------------------ execution


class DevicesMissing(PlugNProduceError):
    """Devices of the cell that discovery did not find."""


def runs_folder() -> Path:
    """Where run journals go unless told otherwise: ``PNP_RUNS``, else ``runs`` in the user's state folder
    (:func:`plugnproduce.folders.runs_folder`)."""
    return folders.runs_folder()


def new_run_id(task_name: str) -> str:
    """A run id that sorts by start time: ``20261123-101500-bin-picking-1a2b``."""
    return f"{time.strftime('%Y%m%d-%H%M%S')}-{task_name}-{secrets.token_hex(2)}"


DISCOVERY_SECONDS = 10.0
"""How long a run or a live check waits for the cell's devices on the network, unless told."""
SIMULATED_DISCOVERY_SECONDS = 60.0
"""The same for the devices a run simulates itself: they are up, so only a busy machine delays their answers."""

DEFAULT_BIN_PARTS = 5
"""Parts in the simulated bin (placed by seed 0 unless told) that a simulated run of a task taking a reported
value gets when no bin is asked for (``--bin-parts``)."""


def default_bin_parts(task_or_path: TaskArg) -> int | None:
    """How many parts a simulated bin needs for a run of this task when none was asked for:
    :data:`DEFAULT_BIN_PARTS` when the task loops until (or while) an outcome and a step takes a value another
    step reports (a data link, such as the pose where a localisation found a part), so that the parts it finds
    are taken out and the loop ends when the bin is empty; None for any other task (the simulated devices report
    their charts' values, and a bin would refuse a move to a fixed pose where no part lies)."""
    the_task = _as_task(task_or_path)
    takes = any(isinstance(v, Link) for step in the_task.steps for v in step.params.values())
    waits = any(loop.until or loop.while_outcome for loop in the_task.loops)
    return DEFAULT_BIN_PARTS if takes and waits else None


async def find_devices(live: LiveCell, wanted: list[str], timeout: float) -> Cell:
    """Wait until discovery has found every wanted device; the live cell's devices with their real endpoints."""
    deadline = asyncio.get_running_loop().time() + timeout
    while missing := [d for d in wanted if d not in {x.id for x in live.cell.devices}]:
        left = deadline - asyncio.get_running_loop().time()
        if left <= 0:
            raise DevicesMissing(f"device(s) {', '.join(missing)} of the cell not found on the network "
                                 f"within {timeout:g} s")
        with contextlib.suppress(TimeoutError):
            await live.next_change(left)
    return Cell(live.cell.name, tuple(live.cell.device(d) for d in wanted))


async def run_task(
    task_or_path: Task | str | Path,
    cell_or_path: Cell | str | Path,
    *,
    simulate: bool = False,
    faults: str = "",
    journal: Path | None = None,
    observer: RecordObserver | None = None,
    started: Callable[[TaskRun], None] | None = None,
    discovery_timeout: float | None = None,
    progress: Callable[[str], None] | None = None,
    knowledge: Knowledge | None = None,
    bin_parts: int | None = None,
    bin_seed: int = 0,
    assume_initial: bool = False,
) -> RunReport:
    """Check and generate a task, find the cell's devices by discovery, run the task chart against them.

    With ``simulate`` the cell's devices are simulated for the run, on a private SSDP network,
    with ``faults`` injected (see :func:`plugnproduce.sim.cell.parse_faults`), working on a
    simulated bin of ``bin_parts`` parts placed by ``bin_seed`` if given. ``started`` is
    given the run once it exists (to stop it); ``discovery_timeout`` bounds the wait for the devices
    (default :data:`DISCOVERY_SECONDS`, simulated: :data:`SIMULATED_DISCOVERY_SECONDS`); ``progress`` is told
    each phase as it begins (checking, generating, starting devices, discovering, running). The task is
    checked and generated from the state each device reports once discovered (:func:`reported_states`), or, with
    ``assume_initial``, from the charts' initial states before discovery. Raises :class:`ImplausibleTask`
    before any command goes out.
    """
    from plugnproduce.discovery import LiveCell
    from plugnproduce.protocols.upnp import network_from_env, private_network
    from plugnproduce.sim.bin import SimulatedBin
    from plugnproduce.sim.cell import SimulatedCell, parse_faults

    say = progress or (lambda _: None)
    the_task, (the_cell, k) = _as_task(task_or_path), _context(cell_or_path, knowledge)
    generated: GeneratedTask | None = None
    if assume_initial:
        say("checking the task in the cell")
        generated = plan_run(the_task, the_cell, k, progress=say)
    journal = journal or runs_folder() / f"{new_run_id(the_task.name)}.jsonl"
    network = private_network() if simulate else network_from_env()
    async with contextlib.AsyncExitStack() as stack:
        if simulate:
            say(f"starting {len(the_cell.devices)} simulated device(s) on loopback")
            parts = SimulatedBin(bin_parts, bin_seed) if bin_parts is not None else None
            sim = SimulatedCell(the_cell, network=network, faults=parse_faults(faults, the_cell.devices), bin=parts)
            await stack.enter_async_context(sim)
        say(f"discovering devices: {', '.join(d.id for d in the_cell.devices)}")
        wanted = [d.id for d in the_cell.devices]
        live = await stack.enter_async_context(LiveCell(k.taxonomy, network=network, name=the_cell.name,
                                                        expected=wanted))
        devices = await find_devices(live, wanted, discovery_timeout or (SIMULATED_DISCOVERY_SECONDS if simulate
                                                                         else DISCOVERY_SECONDS))
        if generated is None:
            say("asking each device its state; checking the task from there")
            generated = plan_run(the_task, the_cell.reported(await reported_states(devices)), k, progress=say)
        say("running")
        run = start_run(generated, devices, journal, observer, prefixes=k.prefixes)
        if started is not None:
            started(run)
        follow = asyncio.create_task(_follow_unplugs(live, run))
        try:
            return await run.run()
        finally:
            follow.cancel()


class StateNotReported(PlugNProduceError):
    """A device of a live cell did not report its state."""


async def reported_states(devices: Cell, timeout: float | None = None) -> dict[str, str]:
    """Ask every device of a live cell (``devices``: their real endpoints) its current state over its protocol,
    all at once; each answer bounded by ``timeout`` (default: the device's command timeout)."""
    from plugnproduce.executor.links import query_state

    async def one(device: DeviceDescription) -> str:
        try:
            state = await query_state(device, timeout or device.command_timeout)
        except PlugNProduceError as exc:
            raise StateNotReported(f"device {device.id} did not report its state ({exc}); to plan from its chart's "
                                   "initial state instead, give --assume-initial") from None
        if state not in {s.id for s in device.states}:
            raise StateNotReported(f"device {device.id} reports state {state!r}, which its device state chart "
                                   f"{Path(device.chart_file).name} does not have")
        return state

    states = await asyncio.gather(*(one(d) for d in devices.devices))
    return {d.id: x for d, x in zip(devices.devices, states, strict=True)}


async def live_cell(cell_or_path: CellArg, knowledge: Knowledge | None = None,
                    discovery_timeout: float = DISCOVERY_SECONDS) -> Cell:
    """The cell with each device in the state it reports: its devices found by discovery (on the network
    ``PNP_SSDP_PORT`` names) and asked their states. For ``check``, ``repair`` and ``explain`` on a live cell."""
    from plugnproduce.discovery import LiveCell
    from plugnproduce.protocols.upnp import network_from_env

    the_cell, k = _context(cell_or_path, knowledge)
    wanted = [d.id for d in the_cell.devices]
    async with LiveCell(k.taxonomy, network=network_from_env(), name=the_cell.name, expected=wanted) as live:
        devices = await find_devices(live, wanted, discovery_timeout)
        return the_cell.reported(await reported_states(devices))


def plan_run(task_or_path: TaskArg, cell_or_path: CellArg, knowledge: Knowledge | None = None,
             progress: Callable[[str], None] | None = None) -> GeneratedTask:
    """Check a task and generate only what a run needs: the task chart (no closed-world chart, no device
    programs, no chart written). Raises :class:`ImplausibleTask` for an implausible task."""
    the_task, (the_cell, k) = _as_task(task_or_path), _context(cell_or_path, knowledge)
    if not (result := check(the_task, the_cell, k)).plausible:
        raise ImplausibleTask(result)
    if progress is not None:
        progress(f"generating the charts of {len(the_task.steps)} step(s)")
    return _generate_task(the_task, the_cell, result, k)


def start_run(generated: GeneratedTask, devices: Cell, journal: Path,
              observer: RecordObserver | None = None, prefixes: Mapping[str, str] | None = None) -> TaskRun:
    """A run of a planned task (:func:`plan_run`) against ``devices`` (a cell whose devices carry their
    real endpoints), journalling into ``journal``; it starts when its ``run()`` is awaited.

    Both faces start runs this way: ``pnp run`` after discovering the cell's devices
    (:func:`run_task`), the HMI with the devices its cell source follows.
    """
    from plugnproduce.executor.run import TaskRun

    return TaskRun(generated, devices, journal, observer, prefixes)


async def _follow_unplugs(live: LiveCell, run: TaskRun) -> None:
    async for change in live.changes():
        if change.kind == "unplug":
            run.device_lost(change.device, "the device left the network (SSDP byebye)")


def report(run: str | Path | None = None) -> RunRecord:
    """A run's journal, by path or by run id (in :func:`runs_folder`); without either, the latest run's."""
    from plugnproduce.executor.journal import read_journal

    if run is None:
        past = runs()
        if not past:
            raise PlugNProduceError(f"no runs yet in {runs_folder()}")
        return read_journal(past[0].path)
    path = Path(run)
    if not path.exists() and not path.suffix:
        path = runs_folder() / f"{run}.jsonl"
    return read_journal(path)


def runs() -> list[RunSummary]:
    """The past runs in :func:`runs_folder`, newest first."""
    from plugnproduce.executor.history import list_runs

    return list_runs(runs_folder())


def impact(extensions: list[Path], cell_files: list[Path] | None = None,
           knowledge: Knowledge | None = None) -> Impact:
    """What adding the TBox files ``extensions`` to ``knowledge`` changes: offered commands per cell
    (default: every cell of the loaded libraries), catalogue roles, the libraries' tasks, and the
    validation findings (shapes, structure) of every catalogue device and cell, before and after."""
    from plugnproduce.reasoning.impact import impact as compute

    return compute(_k(knowledge), extensions, cell_files, _findings)


def _findings(k: Knowledge, files: Sequence[Path]) -> set[tuple[str, int, str]]:
    """What validating ``files`` against ``k`` finds, as (file, line, message)."""
    from plugnproduce.validation import validate_paths

    return {(p.file, p.line, p.message) for p in validate_paths(list(files), k).problems}


def export_ontology(fmt: str = "rdfxml", inferred: bool = False, knowledge: Knowledge | None = None) -> bytes:
    """The merged TBox of ``knowledge`` as one ontology in ``fmt`` (``rdfxml``, ``turtle``, ``owlxml``); with
    ``inferred``, the hierarchy HermiT derived as asserted axioms annotated ``pnp:inferredBy "HermiT"``."""
    from plugnproduce.ontology.export import merged_tbox, serialise

    k = _k(knowledge)
    sources = [lib.name for lib in k.libraries] or ["the pnp ontology"]
    return serialise(merged_tbox(k.tbox(), k.taxonomy, sources, inferred), fmt)
