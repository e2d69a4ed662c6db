"""The names the generated Task State Chart gives its datamodel variables and its ending states.

Code generation writes them into the chart; the executor and the verification read them while the
chart runs. Both take them from here, so that neither reaches into the other for a name.
"""

from __future__ import annotations

PLAN, STEP, VALUES = "pnp_plan", "pnp_step", "pnp_values"
"""Task chart datamodel: the chart each step runs (then 0), how many steps have ended, and each
step's parameter values that differ between the steps sharing a chart."""

OUTCOME = "pnp_outcome"
"""The outcome the last step with outcomes in a loop reported."""

DONE, FAILED = "done", "failed"
"""The task chart's final states: every step ended, or the task stopped on a fault."""

NEXT = "next_step"
"""The state that picks the next step's chart from the plan."""


def output_variable(step_name: str, output: str) -> str:
    """The datamodel variable that holds a named step's output (``pnp_out_localize_part_pose``)."""
    return f"pnp_out_{step_name}_{output}"


def branch_variable(index: int) -> str:
    """The datamodel variable holding the outcome the step at position ``index`` reported (it has branches)."""
    return f"pnp_branch_{index}"


def rounds(n: int) -> str:
    """The datamodel variable counting the iterations of loop ``n`` (1-based)."""
    return f"pnp_rounds_{n}"
