"""Input predicates: what the encodings read (devices, processes, configurations, tasks, repair set-up)."""

from __future__ import annotations

from plugnproduce.reasoning.asp.terms import Atom, predicate

# ------------------------------------------------------------------ input: devices


@predicate("device")
class Device(Atom):
    """A known device (of the cell or of the catalogue)."""

    d: str


@predicate("has_skill")
class HasSkill(Atom):
    """Device ``d`` has skill ``s`` (declared, implied by its class, or a super-skill of those)."""

    d: str
    s: str


@predicate("cost")
class Cost(Atom):
    """Price of device ``d`` (whole currency units)."""

    d: str
    k: int


@predicate("chart_state")
class ChartState(Atom):
    """State ``x`` of device ``d``'s chart."""

    d: str
    x: str


@predicate("state_is")
class StateIs(Atom):
    """State ``x`` of ``d`` is annotated with a concept that ``c`` subsumes (closed under the taxonomy)."""

    d: str
    x: str
    c: str


@predicate("initial")
class Initial(Atom):
    """``x`` is the power-up state of ``d``."""

    d: str
    x: str


@predicate("edge")
class Edge(Atom):
    """A transition of ``d``'s chart from ``x`` to ``y``."""

    d: str
    x: str
    y: str


@predicate("leaves")
class Leaves(Atom):
    """Playing role ``r`` of ``p`` from state ``x`` leaves ``d`` in state ``y`` (code generation's path search)."""

    p: str
    r: str
    d: str
    x: str
    y: str


@predicate("recovers")
class Recovers(Atom):
    """After a step that started ``d`` in a wrong state, the check assumes ``d`` is where ``r`` leaves it: ``y``."""

    p: str
    r: str
    d: str
    y: str


@predicate("missing_arg")
class MissingArg(Atom):
    """Playing role ``r`` of ``p``, ``d`` waits for request ``req`` needing argument ``q`` ``p`` lacks."""

    p: str
    r: str
    d: str
    req: str
    q: str


# ------------------------------------------------------------------ input: processes


@predicate("process")
class Process(Atom):
    """A process command."""

    p: str


@predicate("role")
class Role(Atom):
    """``r`` is a role of ``p``."""

    p: str
    r: str


@predicate("role_order")
class RoleOrder(Atom):
    """``r`` is the ``k``-th role of ``p`` (by name)."""

    p: str
    k: int
    r: str


@predicate("nroles")
class NRoles(Atom):
    """``p`` has ``n`` roles."""

    p: str
    n: int


@predicate("requires")
class Requires(Atom):
    """Role ``r`` of ``p`` requires skill ``s``."""

    p: str
    r: str
    s: str


@predicate("region_state")
class RegionState(Atom):
    """The ``i``-th state role ``r``'s region of ``p`` visits has concept ``c`` (1: start state)."""

    p: str
    r: str
    i: int
    c: str


@predicate("param")
class Param(Atom):
    """``p`` declares parameter ``n`` of datatype ``ty`` (decimal, integer, boolean, string, pose)."""

    p: str
    n: str
    ty: str


@predicate("param_min")
class ParamMin(Atom):
    """Lowest allowed value of a numeric parameter, in thousandths."""

    p: str
    n: str
    v: int


@predicate("param_max")
class ParamMax(Atom):
    """Highest allowed value of a numeric parameter, in thousandths."""

    p: str
    n: str
    v: int


@predicate("param_role")
class ParamRole(Atom):
    """Parameter ``n`` of ``p`` goes to the device bound to role ``r``."""

    p: str
    n: str
    r: str


@predicate("default_refused")
class DefaultRefused(Atom):
    """Device ``d`` refuses the default value of ``p``'s parameter ``n`` by its own limits."""

    p: str
    n: str
    d: str


# ------------------------------------------------------------------ input: configurations and tasks


@predicate("config")
class Config(Atom):
    """A cell configuration."""

    c: str


@predicate("member")
class Member(Atom):
    """Device ``d`` is plugged into configuration ``c``."""

    c: str
    d: str


@predicate("catalogue")
class Catalogue(Atom):
    """A device a repair may add to the cell."""

    d: str


@predicate("step")
class StepFact(Atom):
    """Step ``i`` of task ``t`` runs process command ``p``."""

    t: str
    i: int
    p: str


@predicate("bind")
class Bind(Atom):
    """Step ``i`` of ``t`` binds role ``r`` to device ``d`` explicitly."""

    t: str
    i: int
    r: str
    d: str


@predicate("given")
class Given(Atom):
    """Step ``i`` of ``t`` gives a value for parameter ``n``."""

    t: str
    i: int
    n: str


@predicate("value_kind")
class ValueKind(Atom):
    """The value given for ``n`` is of kind ``k`` (decimal, integer, boolean, string, pose)."""

    t: str
    i: int
    n: str
    k: str


@predicate("value_num")
class ValueNum(Atom):
    """The numeric value given for ``n``, in thousandths."""

    t: str
    i: int
    n: str
    v: int


@predicate("value_refused")
class ValueRefused(Atom):
    """Device ``d`` refuses the value step ``i`` of ``t`` sends for ``n`` (given or default): beyond the device's
    limits, or a given value no request of its chart accepts."""

    t: str
    i: int
    n: str
    d: str


@predicate("check")
class Check(Atom):
    """Check task ``t`` in configuration ``c``."""

    c: str
    t: str


# ------------------------------------------------------------------ input: repair


@predicate("repair")
class RepairScope(Atom):
    """Repair task ``t`` in configuration ``c``."""

    c: str
    t: str


@predicate("slot")
class Slot(Atom):
    """Slot ``s`` of the repair horizon."""

    s: int


@predicate("home")
class Home(Atom):
    """Slot ``s`` is where original step ``i`` runs unless moved or removed."""

    s: int
    i: int


@predicate("gap")
class Gap(Atom):
    """Slot ``s`` is the ``j``-th slot for commands inserted before original step ``i``."""

    s: int
    i: int
    j: int


@predicate("exit_state")
class ExitState(Atom):
    """A repaired window must leave device ``d`` in chart state ``x`` (a later step expects it there)."""

    d: str
    x: str


@predicate("edit_cost")
class EditCost(Atom):
    """The cost of an edit kind (``insert`` per process, ``add`` per device), in hundredths."""

    kind: str
    key: str
    k: int


@predicate("tie_price")
class TiePrice(Atom):
    """A catalogue device's price in hundredths, to prefer the cheaper of two purchases of equal cost when the
    costs leave prices out."""

    a: str
    price: int


@predicate("max_inserts")
class MaxInserts(Atom):
    """At most ``m`` commands may be inserted."""

    m: int
