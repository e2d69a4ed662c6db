"""What verification answers: proved, refuted with the shortest trace, or inconclusive within its budget."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Final, Literal

Verdict = Literal["proved", "refuted", "inconclusive"]
PROVED: Final = "proved"
REFUTED: Final = "refuted"
INCONCLUSIVE: Final = "inconclusive"


@dataclass(frozen=True)
class Budget:
    """How far a search may go: configurations explored and seconds spent."""

    max_states: int = 250_000
    seconds: float = 60.0


@dataclass(frozen=True)
class TraceStep:
    """One move of a counterexample: what happened, and the description line it came from."""

    text: str
    where: str
    """``file:line`` of the device chart's transition or state, or of the task's step."""

    def __str__(self) -> str:
        return f"{self.where}: {self.text}"


@dataclass(frozen=True)
class Verification:
    """The answer for one task on one cell."""

    task: str
    cell: str
    verdict: Verdict
    states: int
    """Distinct global configurations explored."""
    transitions: int
    """Moves taken between them."""
    seconds: float
    problem: str = ""
    """For a refuted task: what went wrong at the end of the trace; for an inconclusive one: which budget ran out."""
    trace: list[TraceStep] = field(default_factory=list)

    @property
    def proved(self) -> bool:
        """Every run reaches ``done``."""
        return self.verdict == PROVED

    def to_json(self) -> dict[str, Any]:
        """The answer as JSON data."""
        return {"task": self.task, "cell": self.cell, "verdict": self.verdict, "states": self.states,
                "transitions": self.transitions, "seconds": round(self.seconds, 3), "problem": self.problem,
                "trace": [{"where": s.where, "step": s.text} for s in self.trace]}

    def lines(self) -> list[str]:
        """The answer as text, one line each."""
        head = (f"task {self.task} on cell {self.cell}: {self.verdict} "
                f"({self.states} states, {self.transitions} transitions, {self.seconds:.2f} s)")
        if self.verdict == PROVED:
            return [head + "; every interleaving reaches done"]
        out = [head, self.problem]
        if self.trace:
            out.append(f"shortest counterexample ({len(self.trace)} steps):")
            out += [f"  {i}. {s}" for i, s in enumerate(self.trace, 1)]
        return out
