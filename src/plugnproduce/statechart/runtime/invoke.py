"""``<invoke>`` of child SCXML sessions, and files named by ``src`` (``<data src>``, ``<invoke src>``).

A child session shares the parent's clock, trust and I/O processors and runs inside the
parent's :meth:`~plugnproduce.statechart.runtime.interpreter.Interpreter.execute_once`. It talks to
the parent through ``#_parent`` and ``#_<invokeid>``; its top-level final state gives the
parent ``done.invoke.<invokeid>``. Files are read only inside the chart's folder unless
the interpreter is trusted.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lxml import etree

from plugnproduce.errors import PlugNProduceError
from plugnproduce.safeio import parse_xml_bytes, read_bytes
from plugnproduce.statechart.model import Chart
from plugnproduce.statechart.runtime.actions import ActionError, Block, CInvoke, literal, value_of
from plugnproduce.statechart.runtime.events import SCXML_TYPES, Event, EventData

if TYPE_CHECKING:
    from plugnproduce.statechart.runtime.compiled import CState
    from plugnproduce.statechart.runtime.interpreter import Interpreter
    from plugnproduce.statechart.runtime.session import InvokerSession

MAX_CHILD_STEPS = 10_000
"""Most macrosteps an invoked session makes before its parent takes its next event."""


@dataclass(slots=True)
class Invocation:
    """A running invoked session and what the parent needs to talk to it."""

    invokeid: str
    state: CState
    child: Interpreter
    finalize: Block
    autoforward: bool


def resolve_src(src: str, base_dir: Path | None, trusted: bool) -> Path:
    """The file a ``src`` names (``file:name`` or a path), relative to the chart's folder.

    Untrusted charts may read only inside their own folder.
    """
    name = src[len("file:"):] if src.startswith("file:") else src
    if "://" in name:
        raise ActionError(f"src {src!r}: only local files are supported")
    if base_dir is None and not Path(name).is_absolute():
        raise ActionError(f"src {src!r}: the chart has no folder to read it from (use Interpreter.from_file)")
    path = (base_dir / name if base_dir is not None else Path(name)).resolve()
    if not trusted and (base_dir is None or not path.is_relative_to(base_dir.resolve())):
        raise ActionError(f"src {src!r} lies outside the chart's folder; only a trusted interpreter reads it")
    return path


def value_from_file(path: Path) -> Any:
    """A ``<data src>`` value: the XML element for markup, a Python literal, or the text."""
    try:
        data = read_bytes(path)
        if data.lstrip().startswith(b"<"):
            return parse_xml_bytes(data, path).getroot()
        return literal(data.decode("utf-8"))
    except (PlugNProduceError, UnicodeDecodeError) as exc:
        raise ActionError(f"cannot read {path.name}: {exc}") from exc


class Invoker:
    """The invoking half of a session (mixed into the interpreter)."""

    dm: dict[str, Any]
    trusted: bool
    base_dir: Path | None
    external: deque[Event]
    _invocations: dict[str, Invocation]

    def _start_invoke(self: InvokerSession, state: CState, inv: CInvoke) -> None:
        """Start one ``<invoke>`` of ``state``; failures become ``error.execution``."""
        invokeid = inv.node.id or f"{state.id}.{self.new_sendid().rsplit('.', 1)[-1]}"
        try:
            if inv.idlocation is not None:
                inv.idlocation.assign(self.dm, invokeid)
            kind = value_of(self, inv.type) or "scxml"
            if kind not in SCXML_TYPES:
                raise ActionError(f"invoke type {kind!r} is not supported; expected scxml")
            chart, base = self._child_chart(inv)
            values = inv.payload.evaluate(self) or {}
            child = self._spawn(chart, invokeid, dict(values), base)
        except ActionError as exc:  # before its base class: the action's own kind of error
            self._error(exc.kind, f"invoke {invokeid!r} failed: {exc.message}")
            return
        except PlugNProduceError as exc:
            self._error("error.execution", f"invoke {invokeid!r} failed: {exc}")
            return
        except Exception as exc:  # an expression error while evaluating the invoke's attributes
            self._error("error.execution", f"invoke {invokeid!r} failed: {exc}")
            return
        self._invocations[invokeid] = Invocation(invokeid, state, child, inv.finalize, inv.node.autoforward)
        child.start()

    def _child_chart(self: InvokerSession, inv: CInvoke) -> tuple[Chart, Path | None]:
        from plugnproduce.statechart.io.reader import parse_chart, read_chart

        if inv.content is not None:
            value = inv.content.get(self)
            if isinstance(value, Chart):
                return value, self.base_dir
            if isinstance(value, etree._Element):
                value = etree.tostring(value)
            if isinstance(value, str):
                value = value.encode()
            if isinstance(value, bytes):
                return parse_chart(value, "<invoke content>"), self.base_dir
            raise ActionError(f"invoke content is a {type(value).__name__}; expected an SCXML document")
        src = value_of(self, inv.src)
        if src is None:
            raise ActionError("invoke has neither content nor src; expected one of them")
        path = resolve_src(str(src), self.base_dir, self.trusted)
        return read_chart(path), path.parent

    def _from_child(self, invokeid: str | None, event: Event) -> None:
        """An event a child sent to ``#_parent`` (dropped once the invocation is cancelled)."""
        if invokeid is not None and invokeid in self._invocations:
            event.invokeid = invokeid
            self.external.append(event)

    def _before_event(self: InvokerSession, event: Event) -> None:
        """Run ``<finalize>`` for an event from a child; forward the event to autoforwarding children."""
        if event.invokeid is not None:
            invocation = self._invocations.get(event.invokeid)
            if invocation is not None and invocation.finalize:
                self._run(invocation.finalize)
        for invocation in self._invocations.values():
            if invocation.autoforward and invocation.child.running:
                copy = Event(event.name, event.data, event.type, event.sendid, event.origin, event.origintype,
                             event.invokeid)
                invocation.child.external.append(copy)

    def _cancel_invokes(self, state: CState) -> None:
        """Stop the sessions ``state`` invoked (it is being exited)."""
        for invokeid in [i for i, inv in self._invocations.items() if inv.state is state]:
            invocation = self._invocations.pop(invokeid)
            invocation.child._stop()

    def _pump_children(self) -> None:
        """Let invoked sessions process what they have, before the parent takes its next event."""
        for invocation in list(self._invocations.values()):
            child = invocation.child
            for _ in range(MAX_CHILD_STEPS):
                if not child.running or child.execute_once() is None:
                    break

    def _children(self) -> list[Interpreter]:
        return [inv.child for inv in self._invocations.values() if inv.child.running]

    def _child(self, invokeid: str) -> Interpreter | None:
        invocation = self._invocations.get(invokeid)
        return invocation.child if invocation is not None and invocation.child.running else None

    def _done_data(self, values: Any) -> Any:
        return EventData(values) if isinstance(values, dict) and not isinstance(values, EventData) else values
