"""Table-driven tests of the encodings in rules/: a named case is facts + the expected answer sets.

A toy world: gripper ``g`` (states o: Open, c: Closed; o <-> c), robot ``r`` (h: AtPose and
Idle, m: Moving; h <-> m), process ``pick`` (gripper: Open, Closed; robot: Idle, Moving,
AtPose), one-role processes ``close``, ``open`` and ``move``.
"""

from __future__ import annotations

import pytest

from plugnproduce.reasoning.asp import solver
from plugnproduce.resources import rules_path
from tests.reasoning.conftest import answer_sets

GRIPPER = """
device("g"). has_skill("g","Grip"). has_skill("g","Release"). initial("g","o"). cost("g",1000).
chart_state("g","o"). chart_state("g","c"). state_is("g","o","Open"). state_is("g","c","Closed").
edge("g","o","c"). edge("g","c","o").
"""
ROBOT = """
device("r"). has_skill("r","Move"). initial("r","h"). cost("r",30000).
chart_state("r","h"). chart_state("r","m").
state_is("r","h","AtPose"). state_is("r","h","Idle"). state_is("r","m","Moving").
edge("r","h","m"). edge("r","m","h").
"""
PROCESSES = """
process("pick"). role("pick","gripper"). role("pick","robot"). nroles("pick",2).
role_order("pick",1,"gripper"). role_order("pick",2,"robot").
requires("pick","gripper","Grip"). requires("pick","robot","Move").
region_state("pick","gripper",1,"Open"). region_state("pick","gripper",2,"Closed").
region_state("pick","robot",1,"Idle"). region_state("pick","robot",2,"Moving"). region_state("pick","robot",3,"AtPose").
process("close"). role("close","gripper"). nroles("close",1). role_order("close",1,"gripper").
requires("close","gripper","Grip").
region_state("close","gripper",1,"Open"). region_state("close","gripper",2,"Closed").
process("open"). role("open","gripper"). nroles("open",1). role_order("open",1,"gripper").
requires("open","gripper","Release").
region_state("open","gripper",1,"Closed"). region_state("open","gripper",2,"Open").
process("move"). role("move","robot"). nroles("move",1). role_order("move",1,"robot").
requires("move","robot","Move").
region_state("move","robot",1,"Idle"). region_state("move","robot",2,"Moving"). region_state("move","robot",3,"AtPose").
param("close","force","decimal"). param_min("close","force",10000). param_max("close","force",140000).
param("move","speed","integer").
"""
LEAVES = """
leaves(P,"gripper",D,"o","c") :- P = ("pick";"close"), device(D), state_is(D,"o","Open").
leaves("open","gripper",D,"c","o") :- device(D), state_is(D,"c","Closed").
leaves(P,"robot","r","h","h") :- P = ("pick";"move").
recovers(P,R,D,Y) :- leaves(P,R,D,_,Y).
"""
WORLD = GRIPPER + ROBOT + PROCESSES + LEAVES
SECOND_GRIPPER = GRIPPER.replace('"g"', '"h"').replace("1000", "500")

OFFERED = list(solver.rules("bindings", show=False))
CHECK = list(solver.rules("check", show=False))


def cell(*devices: str) -> str:
    return 'config("c").' + "".join(f'member("c","{d}").' for d in devices)


def task(*steps: str, binds: str = "") -> str:
    return "".join(f'step("t",{i},"{p}").' for i, p in enumerate(steps, start=1)) + binds + 'check("c","t").'


OFFERED_CASES = {
    "every role has a device": (
        WORLD + cell("g", "r"), ["offered/2"],
        {'offered("c","pick")', 'offered("c","close")', 'offered("c","open")', 'offered("c","move")'}),
    "no gripper: only the robot's process": (
        WORLD + cell("r"), ["offered/2"], {'offered("c","move")'}),
    "a super-skill fills the role (has_skill is closed)": (
        WORLD.replace('has_skill("g","Grip").', 'has_skill("g","ParallelGrip"). has_skill("g","Grip").')
        + cell("g"), ["can_play/3"],
        {'can_play("close","gripper","g")', 'can_play("open","gripper","g")', 'can_play("pick","gripper","g")',
         'can_play("pick","robot","r")', 'can_play("move","robot","r")'}),
    "a device lacking the Closed state plays no gripping role": (
        WORLD.replace('chart_state("g","c"). ', "").replace('state_is("g","c","Closed").', "")
        .replace('edge("g","o","c"). edge("g","c","o").', "") + cell("g"), ["can_play/3", "offered/2"],
        {'can_play("pick","robot","r")', 'can_play("move","robot","r")'}),
    "states reachable only in the wrong order": (
        WORLD.replace('edge("g","o","c").', "") + cell("g"), ["can_play/3"],
        {'can_play("open","gripper","g")', 'can_play("pick","robot","r")', 'can_play("move","robot","r")'}),
    "one device may fill two roles it can play": (
        WORLD.replace('has_skill("g","Release").', 'has_skill("g","Release"). has_skill("g","Move").')
        .replace('state_is("g","o","Open").', 'state_is("g","o","Open"). state_is("g","o","Idle"). '
                 'state_is("g","o","AtPose"). state_is("g","c","Moving").') + cell("g"),
        ["binding/3"],
        {'binding("c","pick",("g",("g",nil)))', 'binding("c","move",("g",nil))', 'binding("c","close",("g",nil))',
         'binding("c","open",("g",nil))'}),
    "a device with the states a region visits but not the skill plays no role": (
        WORLD + SECOND_GRIPPER.replace('has_skill("h","Release").', "") + cell("h"), ["can_play/3", "offered/2"],
        {'can_play("close","gripper","g")', 'can_play("open","gripper","g")', 'can_play("pick","gripper","g")',
         'can_play("close","gripper","h")', 'can_play("pick","gripper","h")',
         'can_play("pick","robot","r")', 'can_play("move","robot","r")', 'offered("c","close")'}),
    "every valid binding, not just one": (
        WORLD + SECOND_GRIPPER + cell("g", "h", "r"), ["binding/3"],
        {'binding("c","pick",("r",("g",nil)))', 'binding("c","pick",("r",("h",nil)))',
         'binding("c","close",("g",nil))', 'binding("c","close",("h",nil))',
         'binding("c","open",("g",nil))', 'binding("c","open",("h",nil))', 'binding("c","move",("r",nil))'}),
}

EXPLAIN_CASES = {
    "no device with the skill": (
        WORLD + cell("r"), {'no_skill("c","pick","gripper","Grip")', 'no_skill("c","close","gripper","Grip")',
                            'no_skill("c","open","gripper","Release")'}),
    "device lacks a state the region visits": (
        WORLD.replace('chart_state("g","c"). ', "").replace('state_is("g","c","Closed").', "")
        .replace('edge("g","o","c"). edge("g","c","o").', "") + cell("g", "r"),
        {'lacks_state("c","pick","gripper","g",2,"Closed")', 'lacks_state("c","close","gripper","g",2,"Closed")',
         'lacks_state("c","open","gripper","g",1,"Closed")'}),
    "state unreachable from where the device is": (
        WORLD.replace('edge("g","o","c").', "") + cell("g", "r"),
        {'unreachable("c","pick","gripper","g",1,"o","Closed")', 'unreachable("c","close","gripper","g",1,"o","Closed")'}),
}


@pytest.mark.parametrize("facts, show, expected", OFFERED_CASES.values(), ids=OFFERED_CASES.keys())
def test_offered(facts: str, show: list[str], expected: set[str]) -> None:
    assert answer_sets(OFFERED, facts, show) == [expected]


@pytest.mark.parametrize("facts, expected", EXPLAIN_CASES.values(), ids=EXPLAIN_CASES.keys())
def test_explain(facts: str, expected: set[str]) -> None:
    assert answer_sets(OFFERED, facts, ["no_skill/4", "lacks_state/6", "unreachable/7"]) == [expected]


PROBLEMS = ["wrong_state/7", "stuck/6", "no_device/4", "ambiguous/5", "absent/5", "cannot_play/5", "unknown_role/4",
            "unknown_command/4", "bad_type/4", "too_low/5", "too_high/5", "unknown_param/3", "plausible/2"]

CHAIN_CASES = {
    "close then open is plausible": (WORLD + cell("g") + task("close", "open"), {'plausible("c","t")'}),
    "close twice: the gripper is closed, step 2 needs Open": (
        WORLD + cell("g") + task("close", "close"), {'wrong_state("c","t",2,"gripper","g","c","Open")'}),
    "after a wrong start the chain goes on from where the role leaves it": (
        WORLD + cell("g") + task("close", "close", "open"), {'wrong_state("c","t",2,"gripper","g","c","Open")'}),
    "after a wrong start the next step is checked from where the role would have left the device": (
        WORLD + cell("g") + task("close", "close", "close"),
        {'wrong_state("c","t",2,"gripper","g","c","Open")', 'wrong_state("c","t",3,"gripper","g","c","Open")'}),
    "the first use is checked against the initial state": (
        WORLD + cell("g") + task("open"), {'wrong_state("c","t",1,"gripper","g","o","Closed")'}),
    "an unbound role with two fitting devices is ambiguous": (
        WORLD + SECOND_GRIPPER + cell("g", "h") + task("close"),
        {'ambiguous("c","t",1,"gripper","g")', 'ambiguous("c","t",1,"gripper","h")'}),
    "an explicit binding settles it": (
        WORLD + SECOND_GRIPPER + cell("g", "h") + task("close", "close", binds='bind("t",2,"gripper","h").'),
        {'ambiguous("c","t",1,"gripper","g")', 'ambiguous("c","t",1,"gripper","h")'}),
    "explicit bindings on every step: plausible with two grippers": (
        WORLD + SECOND_GRIPPER + cell("g", "h")
        + task("close", "close", binds='bind("t",1,"gripper","g"). bind("t",2,"gripper","h").'),
        {'plausible("c","t")'}),
    "no device can play the role": (WORLD + cell("r") + task("close"), {'no_device("c","t",1,"gripper")'}),
    "bound to a device not in the cell": (
        WORLD + cell("r") + task("close", binds='bind("t",1,"gripper","g").'), {'absent("c","t",1,"gripper","g")'}),
    "bound to a device that cannot play the role": (
        WORLD + cell("g", "r") + task("close", binds='bind("t",1,"gripper","r").'),
        {'cannot_play("c","t",1,"gripper","r")'}),
    "a binding of no role of the process": (
        WORLD + cell("g") + task("close", binds='bind("t",1,"hand","g").'), {'unknown_role("c","t",1,"hand")'}),
    "an unknown command": (WORLD + cell("g") + task("fly"), {'unknown_command("c","t",1,"fly")'}),
    "a value above the maximum": (
        WORLD + cell("g") + task("close") + 'given("t",1,"force"). value_kind("t",1,"force","integer"). '
        'value_num("t",1,"force",200000).', {'too_high("t",1,"force",200000,140000)'}),
    "a value below the minimum": (
        WORLD + cell("g") + task("close") + 'given("t",1,"force"). value_kind("t",1,"force","decimal"). '
        'value_num("t",1,"force",5500).', {'too_low("t",1,"force",5500,10000)'}),
    "an integer is a decimal": (
        WORLD + cell("g") + task("close") + 'given("t",1,"force"). value_kind("t",1,"force","integer"). '
        'value_num("t",1,"force",40000).', {'plausible("c","t")'}),
    "a decimal is not an integer": (
        WORLD + cell("r") + task("move") + 'given("t",1,"speed"). value_kind("t",1,"speed","decimal"). '
        'value_num("t",1,"speed",2500).', {'bad_type("t",1,"speed","integer")'}),
    "an undeclared parameter": (
        WORLD + cell("g") + task("close") + 'given("t",1,"angle"). value_kind("t",1,"angle","integer").',
        {'unknown_param("t",1,"angle")'}),
}


@pytest.mark.parametrize("facts, expected", CHAIN_CASES.values(), ids=CHAIN_CASES.keys())
def test_chain(facts: str, expected: set[str]) -> None:
    assert answer_sets(CHECK, facts, PROBLEMS) == [expected]


def test_devices_a_step_does_not_use_keep_their_state() -> None:
    (model,) = answer_sets(CHECK, WORLD + cell("g", "r") + task("close", "move", "open"), ["at/5"])
    assert {a for a in model if ',"g",' in a} == {
        'at("c","t",1,"g","o")', 'at("c","t",2,"g","c")', 'at("c","t",3,"g","c")', 'at("c","t",4,"g","o")'}


def test_left_by_names_the_step_that_left_the_state() -> None:
    (model,) = answer_sets(CHECK, WORLD + cell("g", "r") + task("close", "move", "open"), ["left_by/5"])
    assert {'left_by("c","t",3,"g",1)', 'left_by("c","t",1,"r",0)', 'left_by("c","t",4,"r",2)'} <= model


def test_a_shared_device_plays_its_roles_in_role_order() -> None:
    # "g" fills both roles of pick: first the gripper region (o -> c), then the robot region from c
    # (Idle at c, Moving at o, AtPose at c). In the other order the robot region would start at o: not Idle.
    world = (WORLD.replace('has_skill("g","Release").', 'has_skill("g","Release"). has_skill("g","Move").')
             .replace('state_is("g","o","Open").', 'state_is("g","o","Open"). state_is("g","c","Idle"). '
                      'state_is("g","o","Moving"). state_is("g","c","AtPose").')
             + 'leaves("pick","robot","g","c","c").')
    (model,) = answer_sets(CHECK, world + cell("g") + task("pick") + 'bind("t",1,"robot","g").',
                           PROBLEMS + ["at/5"])
    assert model == {'at("c","t",1,"g","o")', 'at("c","t",2,"g","c")', 'plausible("c","t")'}


REPAIR = list(solver.rules("repair", show=False))
COSTS = ('edit_cost("insert",P,100+100*N) :- nroles(P,N). edit_cost("remove","",400). edit_cost("swap","",300). '
         'edit_cost("rebind","",200). edit_cost("reset","",100).')


def horizon(steps: int) -> str:
    out = 'repair("c","t").'
    for i in range(1, steps + 1):
        out += f"slot({2 * i - 1}). gap({2 * i - 1},{i},1). slot({2 * i}). home({2 * i},{i})."
    return out


def repair_case(steps: tuple[str, ...], devices: tuple[str, ...], extra: str = "", costs: str = COSTS) -> str:
    body = "".join(f'step("t",{i},"{p}").' for i, p in enumerate(steps, start=1))
    return WORLD + SECOND_GRIPPER + cell(*devices) + body + horizon(len(steps)) + costs + extra


REFUSED = ('given("t",1,"force"). value_kind("t",1,"force","decimal"). value_num("t",1,"force",50000). '
           'param_role("close","force","gripper"). value_refused("t",1,"force","g").')
TAKES = ('given("t",1,"force"). value_kind("t",1,"force","decimal"). value_num("t",1,"force",50000). '
         'param_role("close","force","gripper").')
"""A force every gripper takes: a device refuses only what the case adds."""
ROBOT_GRIPPER = (WORLD.replace('has_skill("g","Release").', 'has_skill("g","Release"). has_skill("g","Move").')
                 .replace('state_is("g","o","Open").', 'state_is("g","o","Open"). state_is("g","c","Idle"). '
                          'state_is("g","o","Moving"). state_is("g","c","AtPose").')
                 .replace('initial("g","o")', 'initial("g","c")') + 'leaves("pick","robot","g","c","c").')
"""Gripper ``g`` can also be the robot of ``pick`` (it starts closed, where it is Idle); only gripper ``h`` can then
be its gripper (it starts open)."""
REPAIR_CASES = {
    "insert the missing open": (repair_case(("close", "close"), ("g",)), [{'edit(insert(2,1,"open"))'}]),
    "swap when inserting costs more": (
        repair_case(("open", "close"), ("g",), costs=COSTS.replace("100+100*N", "900")), [{"edit(swap(1))"}]),
    "remove when nothing cheaper": (
        repair_case(("close", "close"), ("g",), costs=COSTS.replace("100+100*N", "900")),
        [{"edit(remove(1))"}, {"edit(remove(2))"}]),
    "rebind to the other gripper": (
        repair_case(("close", "close"), ("g", "h"), 'bind("t",1,"gripper","g"). bind("t",2,"gripper","g").',
                    COSTS.replace("100+100*N", "900")),
        [{'edit(rebind(2,"gripper","h"))'}, {'edit(rebind(1,"gripper","h"))'}]),
    "add a device from the catalogue": (
        repair_case(("close",), ("r",), 'catalogue("g"). catalogue("h"). edit_cost("add","g",510). '
                    'edit_cost("add","h",505).', COSTS.replace("400", "900")), [{'edit(add("h"))'}]),
    "of two devices that repair alike at one cost, the one with the lower price is bought": (
        repair_case(("close",), ("r",), 'catalogue("g"). catalogue("h"). edit_cost("add","g",500). '
                    'edit_cost("add","h",500). tie_price("g",2100). tie_price("h",1400).', COSTS.replace("400", "900")),
        [{'edit(add("h"))'}]),
    "reset a value that does not fit": (
        repair_case(("close",), ("g",), 'given("t",1,"force"). value_kind("t",1,"force","string").'),
        [{'edit(reset(1,"force"))'}]),
    "reset a value the bound device refuses by its own limits": (
        repair_case(("close",), ("g",), REFUSED), [{'edit(reset(1,"force"))'}]),
    "a device that refuses the default too is not bound at all": (
        repair_case(("close",), ("g",), REFUSED + 'default_refused("close","force","g").'), [{"edit(remove(1))"}]),
    "buy the dearer device that takes the value rather than reset it": (
        repair_case(("close",), ("r",), REFUSED.replace('"g"', '"h"') + 'catalogue("g"). catalogue("h"). '
                    'edit_cost("add","g",510). edit_cost("add","h",505).', COSTS.replace("400", "900")),
        [{'edit(add("g"))'}]),
    "a value is sent to the device of its own role, not to another role's device that would refuse it": (
        ROBOT_GRIPPER + SECOND_GRIPPER + cell("g", "h") + 'step("t",1,"pick").' + horizon(1) + COSTS
        + 'param("pick","force","decimal"). given("t",1,"force"). value_kind("t",1,"force","decimal"). '
          'value_num("t",1,"force",50000). param_role("pick","force","gripper"). value_refused("t",1,"force","g"). '
          'param_role("move","force","robot").', [{'edit(bind(1,"gripper","h"))'}]),
    "a reset is refused only where the device it is sent to refuses the default": (
        repair_case(("close",), ("g", "h"), TAKES + 'value_refused("t",1,"force","g"). '
                    'value_refused("t",1,"force","h"). default_refused("close","force","h").'),
        [{'edit(bind(1,"gripper","g"))', 'edit(reset(1,"force"))'}]),
    "a device that refuses the default but takes the value given keeps it": (
        repair_case(("close",), ("g",), TAKES + 'default_refused("close","force","g").'), [set()]),
    "a reset is held to the default of the step's own command": (
        repair_case(("close",), ("g",), TAKES + 'value_refused("t",1,"force","g"). '
                    'param_role("pick","force","gripper"). default_refused("pick","force","g").'),
        [{'edit(reset(1,"force"))'}]),
    "an inserted command's default is held to the device of its own role only": (
        ROBOT_GRIPPER + SECOND_GRIPPER + cell("g", "h") + 'step("t",1,"open"). bind("t",1,"gripper","h").'
        + horizon(1) + COSTS.replace('edit_cost("insert",P,100+100*N) :- nroles(P,N).',
                                     'edit_cost("insert",P,900) :- process(P), P != "pick". '
                                     'edit_cost("insert","pick",300).').replace('"rebind","",200', '"rebind","",900')
        + 'param_role("pick","force","gripper"). default_refused("pick","force","g").',
        [{'edit(insert(1,1,"pick"))'}]),
    "a value not given is never reset, even at no cost, where only another device refuses its default": (
        repair_case(("close",), ("g", "h"), 'bind("t",1,"gripper","h"). param_role("close","force","gripper"). '
                    'value_refused("t",1,"force","g"). default_refused("close","force","g").',
                    COSTS.replace('"reset","",100', '"reset","",0')), [set()]),
    "an inserted command's defaults need fit only the devices it is bound to": (
        repair_case(("close", "close"), ("g",), 'param_role("open","width","gripper"). catalogue("h"). '
                    'edit_cost("add","h",505). default_refused("open","width","h").'), [{'edit(insert(2,1,"open"))'}]),
    "an inserted command's defaults must fit its device": (
        repair_case(("close", "close"), ("g", "h"), 'bind("t",1,"gripper","g"). bind("t",2,"gripper","g"). '
                    'default_refused("open","width","g"). param_role("open","width","gripper").'),
        [{'edit(rebind(2,"gripper","h"))'}, {'edit(rebind(1,"gripper","h"))'}]),
    "a step of an unknown command is removed": (
        repair_case(("close", "fly", "open"), ("g",)), [{"edit(remove(2))"}]),
    "a binding of an unknown role is dropped": (
        repair_case(("close",), ("g",), 'bind("t",1,"hand","g").'), [{'edit(unbind(1,"hand"))'}]),
    "dropping a binding is priced: removing its step can be cheaper": (
        repair_case(("close",), ("g",), 'bind("t",1,"hand","g").', COSTS.replace('"rebind","",200', '"rebind","",900')),
        [{"edit(remove(1))"}]),
    "rebinding is priced: removing its step can be cheaper": (
        repair_case(("close",), ("g", "r"), 'bind("t",1,"gripper","r").',
                    COSTS.replace('"rebind","",200', '"rebind","",900')), [{"edit(remove(1))"}]),
    "resetting a value is priced: removing its step can be cheaper": (
        repair_case(("close",), ("g",), 'given("t",1,"force"). value_kind("t",1,"force","string").',
                    COSTS.replace('"reset","",100', '"reset","",900')), [{"edit(remove(1))"}]),
    "naming one of two fitting devices is priced: removing the step can be cheaper": (
        repair_case(("close",), ("g", "h"), costs=COSTS.replace('"rebind","",200', '"rebind","",900')),
        [{"edit(remove(1))"}]),
    "at most max_inserts commands are inserted": (
        repair_case(("close", "close"), ("g",), "max_inserts(1)."), [{'edit(insert(2,1,"open"))'}]),
    "beyond max_inserts, steps are removed instead": (
        repair_case(("close", "close", "close"), ("g",), "max_inserts(1)."),
        [{'edit(insert(3,1,"open"))', "edit(remove(1))"}, {'edit(insert(2,1,"open"))', "edit(remove(3))"},
         {'edit(insert(3,1,"open"))', "edit(remove(2))"}, {'edit(insert(2,1,"open"))', "edit(remove(2))"}]),
}


@pytest.mark.parametrize("facts, expected", REPAIR_CASES.values(), ids=REPAIR_CASES.keys())
def test_repair(facts: str, expected: list[set[str]]) -> None:
    found = answer_sets(REPAIR, facts, ["edit/1"], ["--opt-mode=optN"])
    assert sorted(map(sorted, found)) == sorted(map(sorted, expected))


WINDOW = list(solver.rules("window", show=False))
WINDOW_CASES = {
    "no exit state: nothing to repair": (repair_case(("close",), ("g",)), [{'left_in("g","c")'}]),
    "the gripper must leave open: the close goes": (
        repair_case(("close",), ("g",), 'exit_state("g","o").'), [{"edit(remove(1))", 'left_in("g","o")'}]),
    "the exit state the repair reaches anyway": (
        repair_case(("close", "close"), ("g",), 'exit_state("g","c").'),
        [{'edit(insert(2,1,"open"))', 'left_in("g","c")'}]),
    "the window enters where the steps before left it": (
        repair_case(("open",), ("g",)).replace('initial("g","o")', 'initial("g","c")'), [{'left_in("g","o")'}]),
}


@pytest.mark.parametrize("facts, expected", WINDOW_CASES.values(), ids=WINDOW_CASES.keys())
def test_window(facts: str, expected: list[set[str]]) -> None:
    found = answer_sets(WINDOW, facts, ["edit/1", "left_in/2"], ["--opt-mode=optN"])
    assert sorted(map(sorted, found)) == sorted(map(sorted, expected))


ABILITIES = list(solver.rules("abilities", show=False))


def test_abilities_are_of_each_device_alone_and_bad_values_of_the_task_alone() -> None:
    facts = WORLD + SECOND_GRIPPER + task("close") + ('given("t",1,"force"). value_kind("t",1,"force","integer"). '
                                                      'value_num("t",1,"force",200000).')
    (model,) = answer_sets(ABILITIES, facts, ["can_play/3", "bad_value/3"])
    assert {'can_play("pick","gripper","g")', 'can_play("pick","gripper","h")', 'can_play("pick","robot","r")',
            'bad_value("t",1,"force")'} <= model
    assert not any('"r")' in a for a in model if a.startswith('can_play("pick","gripper"'))


def test_every_encoding_file_belongs_to_a_program_and_every_program_names_files_that_exist() -> None:
    named = {name for program in solver.PROGRAMS for name in solver.rules(program)}
    assert named == {f.name for f in rules_path().glob("*.lp")}


HANDOVER = """
process("handover"). role("handover","holder"). role("handover","robot"). role("handover","gripper").
nroles("handover",3). role_order("handover",1,"holder"). role_order("handover",2,"robot").
role_order("handover",3,"gripper").
requires("handover","holder","Grip"). requires("handover","robot","Move"). requires("handover","gripper","Release").
region_state("handover","holder",1,"Open"). region_state("handover","holder",2,"Closed").
region_state("handover","robot",1,"Idle"). region_state("handover","robot",2,"Moving").
region_state("handover","robot",3,"AtPose").
region_state("handover","gripper",1,"Closed"). region_state("handover","gripper",2,"Open").
leaves("handover","holder",D,"o","c") :- device(D), state_is(D,"o","Open").
leaves("handover","gripper",D,"c","o") :- device(D), state_is(D,"c","Closed").
leaves("handover","robot","r","h","h").
"""


def test_a_device_in_the_first_and_last_of_three_roles_keeps_one_state_through_the_step() -> None:
    # the gripper holds (o -> c) while the robot moves, then releases (c -> o): it plays role 1 and role 3,
    # and between them it waits in c while role 2 (not its own) runs; other processes order "gripper" first
    (model,) = answer_sets(CHECK, WORLD + HANDOVER + cell("g", "r") + task("handover", "close"), PROBLEMS + ["at/5"])
    assert model == {'at("c","t",1,"g","o")', 'at("c","t",2,"g","o")', 'at("c","t",3,"g","c")',
                     'at("c","t",1,"r","h")', 'at("c","t",2,"r","h")', 'at("c","t",3,"r","h")', 'plausible("c","t")'}


WIDE = """
device("k"). has_skill("k","Grip"). initial("k","w").
chart_state("k","o"). chart_state("k","c"). chart_state("k","w"). chart_state("k","x").
state_is("k","o","Open"). state_is("k","c","Closed"). state_is("k","w","Open"). state_is("k","x","Closed").
edge("k","o","c"). edge("k","c","o"). edge("k","w","x"). edge("k","x","w").
leaves("close","gripper","k","w","x").
"""


def test_a_role_leaves_the_device_where_its_own_start_leads_not_where_another_start_would() -> None:
    # "k" opens narrow (o) or wide (w) and closes from each to its own closed state (c, x); it starts wide
    (model,) = answer_sets(CHECK, WORLD + WIDE + cell("k") + task("close"), PROBLEMS + ["at/5"])
    assert model == {'at("c","t",1,"k","w")', 'at("c","t",2,"k","x")', 'plausible("c","t")'}


SQUEEZE = """
process("squeeze"). role("squeeze","gripper"). nroles("squeeze",1). role_order("squeeze",1,"gripper").
requires("squeeze","gripper","Grip").
region_state("squeeze","gripper",1,"Open"). region_state("squeeze","gripper",2,"Closed").
param("squeeze","force","integer"). param_min("squeeze","force",50000). param_max("squeeze","force",60000).
param("squeeze","speed","decimal"). param("squeeze","label","decimal").
"""


def value(kind: str, name: str, number: int | None = None, step: int = 1) -> str:
    """A value the task gives step ``step`` for parameter ``name``, of ``kind`` (and its number in thousandths)."""
    num = f'value_num("t",{step},"{name}",{number}).' if number is not None else ""
    return f'given("t",{step},"{name}"). value_kind("t",{step},"{name}","{kind}"). {num}'


# Two processes declare a parameter of one name with other types and ranges: each step is checked against
# its own process only. A value of the wrong type is that finding alone, not also one of range.
PARAMETER_CASES = {
    "within close's range, below squeeze's": (task("close") + value("integer", "force", 40000), {'plausible("c","t")'}),
    "within close's range, above squeeze's": (task("close") + value("integer", "force", 100000), {'plausible("c","t")'}),
    "a decimal for move's integer speed, though squeeze's speed is a decimal": (
        task("move") + value("decimal", "speed", 2500), {'bad_type("t",1,"speed","integer")'}),
    "an integer for close's text label, though squeeze's label is a decimal": (
        task("close") + 'param("close","label","string").' + value("integer", "label", 3000),
        {'bad_type("t",1,"label","string")'}),
    "a decimal below move's minimum speed is a wrong type only": (
        task("move") + 'param_min("move","speed",1000).' + value("decimal", "speed", 500),
        {'bad_type("t",1,"speed","integer")'}),
    "a decimal above move's maximum speed is a wrong type only": (
        task("move") + 'param_max("move","speed",100000).' + value("decimal", "speed", 900000),
        {'bad_type("t",1,"speed","integer")'}),
}


@pytest.mark.parametrize("facts, expected", PARAMETER_CASES.values(), ids=PARAMETER_CASES.keys())
def test_parameters_are_checked_against_the_steps_own_process(facts: str, expected: set[str]) -> None:
    assert answer_sets(CHECK, WORLD + SQUEEZE + cell("g", "r") + facts, PROBLEMS) == [expected]


GRIP_ONLY = SECOND_GRIPPER.replace('has_skill("h","Release").', "")
"""A second gripper, ``h``, that can close but not open (no Release skill)."""

# What a step's bindings are when the task names devices: the check lists a device bound to a role only when
# the cell has it and it can play that role of the step's own process; each wrong binding is one finding.
BINDING_CASES = {
    "a device not in the cell is not bound": (
        WORLD + cell("r") + task("close", binds='bind("t",1,"gripper","g").'),
        {'absent("c","t",1,"gripper","g")', 'at("c","t",1,"r","h")', 'at("c","t",2,"r","h")'}),
    "a device not in the cell that could not play the role either is only absent": (
        WORLD + cell("g") + task("close", binds='bind("t",1,"gripper","r").'),
        {'absent("c","t",1,"gripper","r")', 'at("c","t",1,"g","o")', 'at("c","t",2,"g","o")'}),
    "a device bound to its role in another process only is not bound here": (
        WORLD + GRIP_ONLY + cell("h") + task("open", binds='bind("t",1,"gripper","h").'),
        {'cannot_play("c","t",1,"gripper","h")', 'at("c","t",1,"h","o")', 'at("c","t",2,"h","o")'}),
    "a device that plays the step's role is bound, whatever other processes it cannot play": (
        WORLD + GRIP_ONLY + cell("h") + task("close", binds='bind("t",1,"gripper","h").'),
        {'bound("c","t",1,"gripper","h")', 'at("c","t",1,"h","o")', 'at("c","t",2,"h","c")', 'plausible("c","t")'}),
    "a binding of an unknown role to a device not in the cell is an unknown role only": (
        WORLD + cell("g") + task("close", binds='bind("t",1,"hand","z").'),
        {'unknown_role("c","t",1,"hand")', 'bound("c","t",1,"gripper","g")', 'at("c","t",1,"g","o")',
         'at("c","t",2,"g","c")'}),
    "a binding in a step of an unknown command is an unknown command only": (
        WORLD + cell("g") + task("fly", binds='bind("t",1,"hand","g").'),
        {'unknown_command("c","t",1,"fly")', 'at("c","t",1,"g","o")', 'at("c","t",2,"g","o")'}),
}


@pytest.mark.parametrize("facts, expected", BINDING_CASES.values(), ids=BINDING_CASES.keys())
def test_bindings_the_task_names(facts: str, expected: set[str]) -> None:
    assert answer_sets(CHECK, facts, PROBLEMS + ["bound/5", "at/5"]) == [expected]


def _gripper(name: str) -> str:
    return GRIPPER.replace('"g"', f'"{name}"')


NO_CLOSED = (_gripper("h").replace('chart_state("h","c"). ', "").replace('state_is("h","c","Closed").', "")
             .replace('edge("h","o","c"). edge("h","c","o").', ""))
"""A gripper ``h`` without a closed state."""
ONE_WAY = _gripper("u").replace('edge("u","o","c").', "")
"""A gripper ``u`` that can open but not close."""
NO_FORCE = _gripper("a") + 'missing_arg("close","gripper","a","grip","force").'
"""A gripper ``a`` whose grip request needs a force that close does not supply."""
REASONS = ["no_skill/4", "lacks_state/6", "unreachable/7", "no_argument/6"]

# Why a process is not offered: each reason is about a role no device of the cell fills, and names only devices of
# the cell that walk as far as the reason says.
REASON_CASES = {
    "no reasons for roles another device of the cell fills": (
        WORLD + NO_CLOSED + ONE_WAY + NO_FORCE + cell("g", "h", "u", "a", "r"), set()),
    "reasons name only devices of the cell": (
        WORLD + NO_CLOSED + ONE_WAY + NO_FORCE + cell("r"),
        {'no_skill("c","pick","gripper","Grip")', 'no_skill("c","close","gripper","Grip")',
         'no_skill("c","open","gripper","Release")'}),
    "a request's missing argument is a reason only for a device that walks the region": (
        WORLD + NO_CLOSED + 'missing_arg("close","gripper","h","grip","force").' + cell("h", "r"),
        {'lacks_state("c","pick","gripper","h",2,"Closed")', 'lacks_state("c","close","gripper","h",2,"Closed")',
         'lacks_state("c","open","gripper","h",1,"Closed")'}),
    "each reason for its own device, for the one process no device fills (a plays pick and open)": (
        WORLD + NO_CLOSED + ONE_WAY + NO_FORCE + cell("h", "u", "a", "r"),
        {'lacks_state("c","close","gripper","h",2,"Closed")', 'unreachable("c","close","gripper","u",1,"o","Closed")',
         'no_argument("c","close","gripper","a","grip","force")'}),
}


@pytest.mark.parametrize("facts, expected", REASON_CASES.values(), ids=REASON_CASES.keys())
def test_reasons_a_process_is_not_offered(facts: str, expected: set[str]) -> None:
    assert answer_sets(OFFERED, facts, REASONS) == [expected]
