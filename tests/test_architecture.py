"""The layers of ``docs/architecture.md``, checked on the source: imports point one way, SCXML is read,
written and named only in ``statechart/``, and the doc's package graph is the one the imports draw.

``python -m tests.test_architecture`` prints the package graph as the doc's mermaid block;
``python -m tests.test_architecture --write`` redraws the block in ``docs/architecture.md``."""

from __future__ import annotations

import ast
import re
import sys
from collections import defaultdict
from pathlib import Path

import pytest

SRC = Path(__file__).parent.parent / "src" / "plugnproduce"

LAYERS = {
    "__main__": 8,  # ``python -m plugnproduce``: the kept help, else the command line
    "cli": 7,  # the command line may also start the web HMI (pnp serve)
    "hmi": 6,
    "controller": 5.5,  # runs a cell: the cell sources, the runs (discovery, executor, sim) over the service
    "service": 5,
    "executor": 4, "sim": 4, "discovery": 4,
    "verification": 3.5,  # explores the generated program (codegen) in the runtime (statechart)
    "batch": 3.5,  # checks a product family in many cells with the reasoning layer; not part of it
    "codegen": 3, "reasoning": 3, "validation": 3, "drawing": 3,
    "planning": 3.2,  # plans from goals with the reasoning layer
    "timing": 3.1,  # cycle time: times the generated charts (codegen) with the devices' durations
    "knowledge": 2.5,  # the loaded libraries: their taxonomy, descriptions and catalogue
    "description": 2,
    "ontology": 1, "statechart": 1, "protocols": 1,
    "chartnames": 0.5,  # the generated task chart's variable names: codegen writes them, the executor reads them
    "resources": 0, "safeio": 0, "folders": 0, "lazy": 0, "deferred": 0, "helpcache": 0, "collector": 0,
    "errors": -1, "digests": -1,
}
"""Rank of each subpackage or top-level module: a module imports only from lower ranks or its own part."""

FACES = ("cli", "hmi")
FACES_MAY_IMPORT = {"service", "controller", "errors", "lazy"}
"""Besides their own presentation code (and the command line the HMI it serves), the faces import only these: the
concepts' types and helpers they name come through the service or the controller."""

REASONING_PARTS = ("asp", "checks", "repairs", "explanation")
"""The parts of ``reasoning/`` in order: each imports only from itself and the parts before it."""

SCXML_NAMESPACE = "http://www.w3.org/2005/07/scxml"


def _modules() -> list[Path]:
    return sorted(p for p in SRC.rglob("*.py") if p.parent != SRC or p.stem in LAYERS)


def _part(module: str) -> str | None:
    """``plugnproduce.codegen.task`` → ``codegen``; None for modules outside the package."""
    parts = module.split(".")
    return parts[1] if parts[0] == "plugnproduce" and len(parts) > 1 else None


def _imports(path: Path) -> set[str]:
    """Every module ``path`` imports (``from plugnproduce import service`` counts as ``plugnproduce.service``),
    including those it imports on first use (``lazy_module("plugnproduce.service")``) and for type checkers."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
            if node.module == "plugnproduce":
                out |= {f"plugnproduce.{a.name}" for a in node.names if a.name != "__version__"}
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "lazy_module"
              and node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
            out.add(node.args[0].value)
    return out


def _own_part(path: Path) -> str:
    rel = path.relative_to(SRC)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(SRC)))
def test_imports_point_down_the_layers(path: Path) -> None:
    own = _own_part(path)
    upward = sorted(m for m in _imports(path) if (part := _part(m)) in LAYERS and part != own
                    and LAYERS[part] >= LAYERS[own])
    assert upward == [], f"{own} (rank {LAYERS[own]}) imports {upward}"


@pytest.mark.parametrize("face", FACES)
def test_the_faces_import_only_the_service_and_the_controller(face: str) -> None:
    allowed = FACES_MAY_IMPORT | set(FACES if face == "cli" else (face,))  # pnp serve starts the HMI
    reached = sorted(f"{p.relative_to(SRC)}: {m}" for p in (SRC / face).rglob("*.py") for m in _imports(p)
                     if (part := _part(m)) is not None and part not in allowed)
    assert reached == []


def test_the_faces_check_sees_an_import_on_first_use_and_for_type_checkers(tmp_path: Path) -> None:
    module = tmp_path / "face.py"
    module.write_text("from typing import TYPE_CHECKING\nfrom plugnproduce.lazy import lazy_module\n"
                      "if TYPE_CHECKING:\n    from plugnproduce.discovery import LiveCell\n"
                      "else:\n    sim = lazy_module('plugnproduce.sim.control')\n", encoding="utf-8")
    assert {"plugnproduce.discovery", "plugnproduce.sim.control"} <= _imports(module)


def test_scxml_is_parsed_written_and_named_only_in_statechart() -> None:
    offenders = [str(p.relative_to(SRC)) for p in SRC.rglob("*.py") if _own_part(p) != "statechart"
                 and SCXML_NAMESPACE in p.read_text(encoding="utf-8")]
    assert offenders == []


def test_codegen_builds_model_objects_not_xml() -> None:
    offenders = [str(p.relative_to(SRC)) for p in (SRC / "codegen").rglob("*.py")
                 if any(m.split(".")[0] == "lxml" or m.startswith("xml.") for m in _imports(p))]
    assert offenders == []


def test_the_executor_takes_the_chart_s_names_from_chartnames_not_codegen() -> None:
    """The executor reads the generated program (codegen's product types) but names its variables and ending
    states through :mod:`plugnproduce.chartnames`, the one place that defines them."""
    names = {"DONE", "FAILED", "NEXT", "OUTCOME", "PLAN", "STEP", "VALUES", "branch_variable", "output_variable",
             "rounds"}
    offenders = []
    for path in [*(SRC / "executor").rglob("*.py"), *(SRC / "verification").rglob("*.py")]:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and _part(node.module or "") == "codegen":
                offenders += [f"{path.relative_to(SRC)}: {a.name}" for a in node.names if a.name in names]
    assert offenders == []


def test_no_reasoning_module_imports_codegen() -> None:
    offenders = [str(p.relative_to(SRC)) for p in (SRC / "reasoning").rglob("*.py")
                 if any(_part(m) == "codegen" for m in _imports(p))]
    assert offenders == []


@pytest.mark.parametrize("part", REASONING_PARTS)
def test_reasoning_parts_import_one_way(part: str) -> None:
    later = {f"plugnproduce.reasoning.{p}" for p in REASONING_PARTS[REASONING_PARTS.index(part) + 1:]}
    offenders = sorted(f"{p.relative_to(SRC)} imports {m}" for p in (SRC / "reasoning" / part).rglob("*.py")
                       for m in _imports(p) if m == "plugnproduce.reasoning"
                       or any(m == x or m.startswith(x + ".") for x in later))
    assert offenders == []


def test_no_package_holds_more_than_15_modules_flat() -> None:
    folders = [SRC, *(d for d in SRC.rglob("*") if d.is_dir())]
    crowded = {str(d.relative_to(SRC)): n for d in folders
               if (n := len([m for m in d.glob("*.py") if m.name != "__init__.py"])) > 15}
    assert crowded == {}



def test_no_package_names_a_function_as_one_of_its_modules() -> None:
    """A package that hands out a name on first use loses it to its module of that name once anything imports the
    module (the import binds the module there), so ``controller.teach(...)`` failed after a test imported
    ``controller.teach``'s module."""
    clashes = {}
    for init in SRC.rglob("__init__.py"):
        exported = set(re.findall(r'^    "(\w+)",$', init.read_text(encoding="utf-8"), re.M))  # its __all__
        modules = {m.stem for m in init.parent.glob("*.py")} | {d.name for d in init.parent.iterdir() if d.is_dir()}
        if clash := sorted(exported & modules):
            clashes[str(init.parent.relative_to(SRC))] = clash
    assert clashes == {}

# ---------------------------------------------------------------- the doc's package graph

DOC = Path(__file__).parent.parent / "docs" / "architecture.md"
_GRAPH = re.compile(r"```mermaid\n(graph TD\n.*?)```", re.S)


def parts() -> list[str]:
    """Every package of ``src/plugnproduce`` and every top-level module but ``__init__``."""
    packages = {p.parent.name for p in SRC.glob("*/*.py")}
    modules = {p.stem for p in SRC.glob("*.py") if p.stem != "__init__"}
    return sorted(packages | modules)


def package_graph() -> set[tuple[str, str]]:
    """``(a, b)`` for each part ``a`` with a module that imports a module of another part ``b``."""
    known = set(parts())
    edges = set()
    for path in SRC.rglob("*.py"):
        if path == SRC / "__init__.py":
            continue
        own = _own_part(path)
        edges |= {(own, part) for m in _imports(path) if (part := _part(m)) in known and part != own}
    return edges


def _rank(part: str) -> float:
    return LAYERS.get(part, -2)


def mermaid(edges: set[tuple[str, str]]) -> str:
    """The graph as the doc draws it: one line per part, its imports after ``-->``, the highest layers first;
    a part that imports nothing of the package and is imported by nothing stands on a line of its own."""
    out: dict[str, list[str]] = defaultdict(list)
    for a, b in edges:
        out[a].append(b)
    order = sorted(parts(), key=lambda p: (-_rank(p), p))
    lines = ["graph TD"]
    for part in order:
        targets = sorted(out.get(part, []), key=lambda p: (-_rank(p), p))
        if targets:
            lines.append(f"  {part} --> {' & '.join(targets)}")
        elif not any(part in ts for ts in out.values()):
            lines.append(f"  {part}")
    return "\n".join(lines) + "\n"


def doc_graph(text: str) -> tuple[set[tuple[str, str]], set[str]]:
    """The edges and the nodes of the doc's mermaid package graph (``a --> b & c`` lines, lone ``a`` lines)."""
    found = _GRAPH.search(text)
    assert found is not None, f"{DOC.name} has no ```mermaid graph TD block"
    edges, nodes = set(), set()
    for line in found.group(1).splitlines()[1:]:
        line = line.split("%%")[0].strip()
        if not line:
            continue
        sources, _, targets = line.partition("-->")
        left = [n.strip() for n in sources.split("&")]
        right = [n.strip() for n in targets.split("&")] if targets else []
        nodes |= {*left, *right}
        edges |= {(a, b) for a in left for b in right}
    return edges, nodes


def test_the_docs_package_graph_is_the_one_the_imports_draw() -> None:
    drawn, _ = doc_graph(DOC.read_text(encoding="utf-8"))
    actual = package_graph()
    missing, extra = sorted(actual - drawn), sorted(drawn - actual)
    if missing or extra:
        pytest.fail(f"{DOC.name} lacks the imports {', '.join(f'{a} --> {b}' for a, b in missing) or '(none)'} "
                    f"and draws {', '.join(f'{a} --> {b}' for a, b in extra) or '(none)'}, which do not exist; "
                    "redraw it with: python -m tests.test_architecture --write", pytrace=False)


def test_the_doc_names_every_package_and_top_level_module() -> None:
    text = DOC.read_text(encoding="utf-8")
    _, nodes = doc_graph(text)
    unnamed, unknown = sorted(set(parts()) - nodes), sorted(nodes - set(parts()))
    if unnamed or unknown:
        pytest.fail(f"{DOC.name}'s graph leaves out {', '.join(unnamed) or '(none)'} and names "
                    f"{', '.join(unknown) or '(none)'}, which is no package or top-level module", pytrace=False)


def test_every_part_has_a_layer() -> None:
    assert sorted(p for p in parts() if p not in LAYERS) == []


def _redraw() -> None:
    text = DOC.read_text(encoding="utf-8")
    found = _GRAPH.search(text)
    assert found is not None
    DOC.write_text(text[:found.start(1)] + mermaid(package_graph()) + text[found.end(1):], encoding="utf-8")



def test_no_runtime_part_escapes_the_type_checker_through_any() -> None:
    """The runtime's parts reach one another through the Protocols of ``statechart/runtime/session.py``."""
    escapes = re.compile(r":\s*Any\s*=\s*self\b|type:\s*ignore\[arg-type\]")
    offenders = [f"{p.relative_to(SRC)}:{n}" for p in (SRC / "statechart" / "runtime").glob("*.py")
                 for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), start=1) if escapes.search(line)]
    assert offenders == []


if __name__ == "__main__":
    if sys.argv[1:] == ["--write"]:
        _redraw()
    else:
        print(mermaid(package_graph()), end="")
