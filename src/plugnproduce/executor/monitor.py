"""The run-time monitor: every argument of a request, held to the bound device's contract before it goes out.

The plausibility check proves what it can before a run; the values it cannot know (an earlier
step's output, a value a device reports) are known only now. Immediately before a request is
sent, each argument its device's transition accepts is judged by the one definition of "within
contract" (:func:`plugnproduce.description.quantities.contracts.breach`): datatype, size, unit, minimum,
maximum and reach; a required argument must be there. A number given in another unit than the
contract's (an output in ``mm``, a value that changes between loop iterations) goes out converted.

A breach names the argument, its value and where the value came from: the task's value at its
line, a default, or the output a device reported at a step (``part_pose reported by
binpicking-pc at step 4``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from plugnproduce.chartnames import output_variable
from plugnproduce.codegen.task import GeneratedTask, StepChart
from plugnproduce.description.model import Argument, Cell, DeviceDescription, Link
from plugnproduce.description.quantities.contracts import breach, in_contract_unit, shorten
from plugnproduce.ontology.iris import local_name


@dataclass(frozen=True)
class Breach:
    """An argument the device's contract refuses: the request is not sent."""

    argument: str
    value: object
    source: str
    why: str

    def message(self, device: str, request: str) -> str:
        """One line: what was refused and why."""
        return (f"request {request} not sent: argument {self.argument} = {shorten(self.value)} ({self.source}) "
                f"is beyond the contract of {device}, which {self.why}")


@dataclass(frozen=True)
class _Source:
    text: str
    unit: str


class Monitor:
    """Judges the requests of one run; told of each output a device reports, to name it as a value's source."""

    def __init__(self, generated: GeneratedTask, cell: Cell) -> None:
        self._generated = generated
        self._cell = cell
        self._reported: dict[str, tuple[int, str]] = {}

    def reported(self, step: int | None, device: str, params: Mapping[str, Any]) -> None:
        """A device event at step position ``step`` brought ``params``: note the outputs among them."""
        chart = self._step(step)
        if chart is None or step is None:
            return
        for role, output, variable in chart.produces:
            if chart.binding.get(role) == device and output in params:
                self._reported[variable] = (step, device)

    def check(self, step: int | None, device: str, request: str, params: Mapping[str, Any],
              datamodel: Mapping[str, Any]) -> dict[str, Any] | Breach:
        """The arguments as they go out (numbers in the contract's unit), or the first breach of the contract.

        ``datamodel`` is the task chart's: the outputs kept there tell which parameter a value comes from.
        """
        chart, dev = self._step(step), self._cell.device(device)
        out = dict(params)
        for quantity in _accepted(dev, request):
            name, contract = local_name(quantity), dev.argument(request, quantity)
            source = self._source(chart, dev, contract, params.get(name), datamodel)
            if name not in params:
                if contract.needed:
                    return Breach(name, None, source.text, "requires it; the request lacks it")
                continue
            why = breach(params[name], source.unit, contract)
            if why is not None:
                return Breach(name, params[name], source.text, why)
            out[name] = in_contract_unit(params[name], source.unit, contract)
        return out

    def _step(self, step: int | None) -> StepChart | None:
        steps = self._generated.steps
        return steps[step - 1] if step is not None and 1 <= step <= len(steps) else None

    def _source(self, chart: StepChart | None, device: DeviceDescription, contract: Argument, sent: object,
                datamodel: Mapping[str, Any]) -> _Source:
        """Where the value ``sent`` for ``contract``'s argument comes from, and the unit it is in."""
        own = _Source(f"{device.id}'s own default", contract.unit)
        if chart is None:
            return own
        pars = [p for p in chart.process.parameters if p.quantity == contract.quantity
                and chart.binding.get(p.role) == device.id]
        if not pars:
            return own

        def gives(name: str) -> bool:  # several parameters may go to one request (a pick's pose and its lift)
            value = chart.step.params.get(name)
            if isinstance(value, Link):
                return bool(value.applied(datamodel.get(output_variable(value.step, value.output))) == sent)
            return value is None or value == sent

        given = [p for p in pars if p.name in chart.step.params and gives(p.name)]
        par = next(iter(given), None) or next((p for p in pars if gives(p.name)), pars[0])
        step, task = chart.step, self._generated.task
        value = step.params.get(par.name)
        # codegen writes a fixed number in the contract's unit; a value that varies, in its parameter's unit
        unit = par.unit if par.name in chart.varying else contract.unit
        at = f"step {step.index}"
        if isinstance(value, Link):
            return _Source(self._reported_by(value), self._output_unit(value, par.unit))
        if value is not None:
            return _Source(f"the task's value of {par.name} at {at}, {task.where(step, par.name)}", unit)
        return _Source(f"the default of {par.name} of {chart.process.id} at {at}", unit)

    def _reported_by(self, link: Link) -> str:
        seen = self._reported.get(output_variable(link.step, link.output))
        plus = f" plus the offset {list(link.offset)}" if link.offset is not None else ""
        if seen is None:
            return f"{link.output} of step {link.step}, not reported{plus}"
        return f"{link.output} reported by {seen[1]} at step {seen[0]}{plus}"

    def _output_unit(self, link: Link, fallback: str) -> str:
        producer = next((s for s in self._generated.steps if s.step.name == link.step), None)
        if producer is None:
            return fallback
        return next((o.unit for o in producer.process.outputs if o.name == link.output), fallback)


def _accepted(device: DeviceDescription, request: str) -> tuple[str, ...]:
    """The quantities the device's transitions taking ``request`` accept."""
    return tuple(dict.fromkeys(q for t in device.transitions if t.request and t.request.name == request
                               for q in t.accepts))


