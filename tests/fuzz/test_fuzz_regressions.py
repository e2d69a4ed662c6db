"""The crashers the fuzz campaign found, each kept as a case (issue 15).

Each was a traceback, a message of several lines, or a message repeating the input at
length; each is now one ``file:line: message`` line with at most a short excerpt.
"""

from __future__ import annotations

import logging
import subprocess
import sys
from pathlib import Path

import pytest
from fuzzing import (
    Crash,
    InProcessHmi,
    Workspace,
    check_message,
    run_hmi,
    run_reference,
    run_served,
    run_ssdp,
    run_upnp_description,
    seeds,
    upnp_seeds,
)

from plugnproduce import service
from plugnproduce.description.loader import load_cell, load_device, load_task
from plugnproduce.errors import MAX_EXCERPT, DescriptionError, UnreadableError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.protocols.xirp import MessageError, decode
from plugnproduce.safeio import excerpt, parse_turtle, parse_yaml_node, tidy
from plugnproduce.statechart.io.reader import parse_chart

LONG = "(" * 5000
GRIPPER = dict(seeds("turtle"))["devices/gripper.ttl"].decode()
GRIPPER_CHART = dict(seeds("chart"))["devices/gripper.scxml"].decode()


def _one_line(exc: BaseException, data: bytes | str = LONG) -> str:
    message = str(exc)
    check_message(message, data)
    return message


def test_excerpt_and_tidy_keep_a_message_short() -> None:
    assert excerpt("abc") == "abc"
    assert len(excerpt("x" * 5000)) <= 60 and "…" in excerpt("x" * 5000)
    assert tidy(f"bad value '{LONG}'\non two lines") == f"bad value '{excerpt(LONG)}' on two lines"


def test_issue_15_turtle_syntax_error_is_one_line_without_the_file(tmp_path: Path) -> None:
    path = tmp_path / "d.ttl"
    path.write_text(GRIPPER.replace("pnp:cost 1800 .", "pnp:cost 1800 ;;; ]"))
    with pytest.raises(UnreadableError) as info:
        parse_turtle(path)
    message = _one_line(info.value, GRIPPER)
    assert message.startswith(f"{path}:") and "b'" not in message and "malformed Turtle:" in message


def test_issue_15_odd_iris_leave_no_log_lines_on_the_command_line(tmp_path: Path) -> None:
    path = tmp_path / "d.ttl"
    path.write_text(GRIPPER.replace("<gripper.scxml>", '<http://ex.org/a"b>'))
    proc = subprocess.run([sys.executable, "-m", "plugnproduce", "validate", str(path)], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert "does not look like a valid URI" not in proc.stdout + proc.stderr  # rdflib's warning, quieted by the CLI


def test_issue_15_the_library_leaves_logging_to_the_application() -> None:
    # reading Turtle set rdflib's logger to ERROR on import: configuration inside library code
    code = "import logging, plugnproduce.safeio; print(logging.getLogger('rdflib.term').level)"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.stdout.strip() == str(logging.NOTSET), proc.stderr


@pytest.mark.parametrize("literal", ['"abc"^^xsd:decimal', '"1e999"^^xsd:double', "1" + "0" * 400,
                                     '"NaN"^^xsd:double', '"2020-13-45"^^xsd:date'])
def test_issue_15_a_bad_number_in_a_device_is_refused_at_its_line(tmp_path: Path, taxonomy: Taxonomy,
                                                                   literal: str) -> None:
    (tmp_path / "gripper.scxml").write_text(GRIPPER_CHART)
    path = tmp_path / "gripper.ttl"
    text = GRIPPER.replace("pnp:cost 1800 .", f"pnp:cost {literal} .")
    if "xsd:" in literal:
        text = "@prefix xsd: <http://www.w3.org/2001/XMLSchema#> .\n" + text
    path.write_text(text)
    with pytest.raises(UnreadableError) as info:
        load_device(path, taxonomy)
    assert "cost" in _one_line(info.value, text) and info.value.line is not None
    report = service.validate([path])
    assert report.unreadable and not report.valid


def test_issue_15_a_nul_in_yaml_is_refused_at_its_line(tmp_path: Path) -> None:
    path = tmp_path / "t.yaml"
    path.write_bytes(b"task: t\nsteps:\n  - command: pi\x00ck\n")
    with pytest.raises(UnreadableError) as info:
        parse_yaml_node(path)
    assert info.value.line == 3 and "#x0000" in _one_line(info.value)


@pytest.mark.parametrize("device", ["x" * 5000, "a/" * 600, "ok\\0no", "../devices/" + "y" * 300 + ".ttl"])
def test_issue_15_a_device_path_no_file_could_have_is_refused_at_its_line(tmp_path: Path, taxonomy: Taxonomy,
                                                                           device: str) -> None:
    path = tmp_path / "cell.yaml"
    path.write_text(f'cell: c\ndevices:\n  - "{device}"\n')
    with pytest.raises(DescriptionError) as info:
        load_cell(path, taxonomy)
    assert info.value.line == 3
    _one_line(info.value, device)
    report = service.validate([path])  # no OSError from looking the file up
    assert not report.valid


def test_issue_15_an_unknown_long_key_is_quoted_short(tmp_path: Path) -> None:
    path = tmp_path / "t.yaml"
    path.write_text(f"task: t\nsteps: []\n'{'k' * 1000}': 1\n")
    with pytest.raises(DescriptionError) as info:
        load_task(path)
    assert "unknown key" in _one_line(info.value, "k" * 1000)


@pytest.mark.parametrize("payload", [
    b'<response xmlns="urn:plugnproduce-org:xirp:1" id="1"/>\x00',
    b'<response xmlns="urn:plugnproduce-org:xirp:' + LONG.encode() + b'" id="1"/>',
    b'<response xmlns="urn:plugnproduce-org:xirp:1" id="' + b"9" * 5000 + b'"/>',
    b'<request xmlns="urn:plugnproduce-org:xirp:1" id="1" name="' + LONG.encode() + b'"/>',
    b'<event xmlns="urn:plugnproduce-org:xirp:1" name="e" seq="1" time="2024-' + b"0" * 5000 + b'"/>',
], ids=["nul", "long namespace", "long id", "long name", "long time"])
def test_issue_15_a_bad_xirp_frame_is_one_short_line(payload: bytes) -> None:
    with pytest.raises(MessageError) as info:
        decode(payload, "message from 127.0.0.1:9")
    _one_line(info.value, payload)


@pytest.mark.parametrize("chart", [
    f'<scxml xmlns="http://www.w3.org/2005/07/scxml{LONG}" version="1.0"/>',
    f'<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="{LONG}"><state id="a"/></scxml>',
    f'<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0"><state id="a"><transition event="{LONG}" '
    'target="a"/></state></scxml>',
], ids=["namespace", "initial", "event"])
def test_issue_15_a_bad_chart_is_one_short_line(workspace: Workspace, chart: str) -> None:
    path = workspace.write("devices/gripper.scxml", chart.encode())
    try:
        parse_chart(chart.encode(), path)
    except DescriptionError as exc:
        _one_line(exc, chart)
    problems = service.validate([path]).sorted()  # the schema refuses what the runtime's reader lets through
    assert problems
    for problem in problems:
        check_message(str(problem), chart)


def test_issue_15_a_long_pose_in_a_task_is_quoted_short(workspace: Workspace) -> None:
    text = dict(seeds("task"))["tasks/bin-picking.yaml"].decode()
    text = text.replace("[0.60, -0.20, 0.10, 0, 180, 0]", '"' + "0 " * 3000 + '"')
    path = workspace.write("tasks/bin-picking.yaml", text.encode())
    problems = service.validate([path]).sorted()
    assert problems
    for problem in problems:
        check_message(str(problem), text)


def test_issue_15_a_chart_named_on_two_lines_is_refused_in_one(workspace: Workspace) -> None:
    description = GRIPPER.replace("<gripper.scxml>", "<gripper.scxml\\u000aother.scxml>").encode()
    assert run_served(workspace, "gripper", description, GRIPPER_CHART.encode(),
                      "http://127.0.0.1:8000/dev/description.xml") == "refused"


def test_issue_15_a_long_url_a_device_names_is_quoted_short() -> None:
    assert run_reference("http://127.0.0.1:8000/d.xml", "http://127.0.0.1@evil/" + "[" * 5000) == "refused"
    assert run_reference("http://127.0.0.1:8000/d.xml", "file:///" + "x" * 5000) == "refused"


@pytest.fixture(scope="module")
def hmi(tmp_path_factory: pytest.TempPathFactory) -> InProcessHmi:
    app = InProcessHmi(tmp_path_factory.mktemp("runs"))
    yield app  # type: ignore[misc]
    app.close()


@pytest.mark.parametrize("url", ["/api/runs/" + "%5B" * 3000, "/api/processes/" + "pick" * 1000,
                                 "/api/charts/process/" + "(" * 2000 + ".svg"])
def test_issue_15_an_unknown_name_in_a_url_is_quoted_short(hmi: InProcessHmi, url: str) -> None:
    assert run_hmi(hmi, ("GET", url, {})) == "refused"


def test_the_checker_itself_catches_a_long_quote() -> None:
    with pytest.raises(Crash):
        check_message(f"bad: {GRIPPER[:300]}", GRIPPER)
    with pytest.raises(Crash):
        check_message("two\nlines", "")


def test_issue_15_a_chart_path_from_the_input_is_named_short(workspace: Workspace, taxonomy: Taxonomy) -> None:
    text = GRIPPER.replace("<gripper.scxml>", "<" + "[" * 3000 + ".scxml>")
    path = workspace.write("devices/gripper.ttl", text.encode())
    with pytest.raises(UnreadableError) as info:
        load_device(path, taxonomy)
    _one_line(info.value, text)


def test_issue_15_a_task_sharing_one_value_between_steps_is_written_without_aliases() -> None:
    from plugnproduce.hmi.schemas import TaskIn
    from plugnproduce.hmi.taskfiles import validate_task

    pose = [0.6, -0.2, 0.1, 0, 180, 0]
    steps = [{"command": "place", "params": {"place_pose": pose, "speed": 80}}] * 2  # one list in both steps
    result = validate_task(TaskIn.model_validate({"name": "t", "steps": steps}))
    assert all("anchors" not in p["message"] for p in result["problems"])


def test_issue_15_a_nul_in_a_chart_name_is_refused_at_its_file(workspace: Workspace, taxonomy: Taxonomy) -> None:
    text = GRIPPER.replace("<gripper.scxml>", "<grip%00per.scxml>")
    path = workspace.write("devices/gripper.ttl", text.encode())
    with pytest.raises(UnreadableError) as info:
        load_device(path, taxonomy)
    assert "NUL" in _one_line(info.value, text)


def test_issue_15_every_description_error_is_one_line_with_short_quotes() -> None:
    error = DescriptionError(f"transition target '{LONG}' does not exist;\nexpected a state", "f.scxml", 5)
    assert error.location_message() == f"f.scxml:5: transition target '{excerpt(LONG)}' does not exist; expected a state"
    assert DescriptionError("the gripper's state is the ontology's Released").message == \
        "the gripper's state is the ontology's Released"


def test_issue_15_a_long_unknown_command_or_parameter_in_a_task_is_quoted_short(workspace: Workspace) -> None:
    text = f"task: t\nsteps:\n  - command: 'pick-{'[ <urn:p> ' * 400}'\n  - command: pick\n    params:\n" \
           f"      'grip_force:{'- ' * 2000}': 1\n"
    path = workspace.write("tasks/bin-picking.yaml", text.encode())
    problems = service.validate([path]).sorted()
    assert problems
    for problem in problems:
        check_message(str(problem), text)


def test_issue_15_a_long_field_name_in_a_request_is_quoted_short(hmi: InProcessHmi) -> None:
    task = {"name": "t", "steps": [{"command": "pick", "params": {"(" * 3000: None}}]}
    assert run_hmi(hmi, ("POST", "/api/task/validate", {"json": task})) == "refused"


def test_issue_15_a_long_endpoint_on_another_host_is_quoted_short(workspace: Workspace) -> None:
    endpoint = "xirp://" + "9" * 3000 + ":1"
    description = GRIPPER.replace("xirp://127.0.0.1:0", endpoint).encode()
    assert run_served(workspace, "gripper", description, GRIPPER_CHART.encode(),
                      "http://127.0.0.1:8000/dev/description.xml") == "refused"


def test_issue_15_a_served_chart_named_with_a_null_character_is_refused(workspace: Workspace) -> None:
    description = GRIPPER.replace("<gripper.scxml>", "<gripper\\u0000.scxml>").encode()
    assert run_served(workspace, "gripper", description, GRIPPER_CHART.encode(),
                      "http://127.0.0.1:8000/dev/description.xml") == "refused"


@pytest.mark.parametrize("frame", [
    b"<r><" + b"abcdefghij" * 20 + b"></" + b"klmnopqrst" * 20 + b"></r>",  # lxml names both tags, unquoted
    b"<" + b"abcdefghij" * 30 + b' x="1">',
    b"<a:" + b"qrstuvwxyz" * 20 + b"/>",
])
def test_issue_15_a_malformed_xirp_message_names_the_peer_s_tags_short(frame: bytes) -> None:
    with pytest.raises(MessageError) as info:
        decode(frame, "message from 127.0.0.1:9")
    message = _one_line(info.value, frame)
    assert message.startswith("message from 127.0.0.1:9: malformed XML:")
    assert max(len(word) for word in message.split()) <= MAX_EXCERPT  # each name cut to an excerpt


@pytest.mark.parametrize("value", ["a\\u1", "\\1", "\\g<0>", "x\\ny"])
def test_issue_15_a_backslash_in_a_task_value_is_quoted_as_written(workspace: Workspace, value: str) -> None:
    # pySHACL fills a shape's message in with re.sub: the value was read as a pattern's escapes
    text = dict(seeds("task"))["tasks/bin-picking.yaml"].decode().replace("grip_force: 45", f"grip_force: '{value}'")
    path = workspace.write("tasks/bin-picking.yaml", text.encode())
    problems = [str(p) for p in service.validate([path]).sorted()]
    assert any(p.endswith(f"parameter 'grip_force' takes a number; found {value}") for p in problems), problems


LONG_UDN = "uuid:2fac1" + "0" * 3000


def test_issue_15_an_ssdp_alive_with_a_long_udn_off_its_host_is_refused_short() -> None:
    alive = (f"NOTIFY * HTTP/1.1\r\nHOST: 239.255.255.250:1900\r\nUSN: {LONG_UDN}::upnp:rootdevice\r\n"
             "LOCATION: http://10.0.0.1/d.xml\r\nNT: upnp:rootdevice\r\nNTS: ssdp:alive\r\n\r\n").encode()
    assert run_ssdp(alive) == "refused"


async def test_issue_15_describe_names_a_long_udn_short() -> None:
    from plugnproduce.protocols.upnp import Advertisement, UntrustedUrlError, describe

    with pytest.raises(UntrustedUrlError) as info:
        await describe(Advertisement(LONG_UDN, True, "http://10.0.0.1/" + "d" * 3000, "127.0.0.1"))
    _one_line(info.value, LONG_UDN + "http://10.0.0.1/" + "d" * 3000)


@pytest.mark.parametrize("edit", [
    (b"<relatedStateVariable>A_ARG_TYPE_Capture_Exposure<", b"<relatedStateVariable>A_ARG " + b"{a: " * 300 + b"<"),
    (b"<relatedStateVariable>A_ARG_TYPE_Capture_Exposure<", b"<relatedStateVariable>%YAML 1.1\nA_ARG<"),
])
def test_issue_15_a_malformed_scpd_is_refused_in_one_short_line(edit: tuple[bytes, bytes]) -> None:
    root, scpd = upnp_seeds()
    assert edit[0] in scpd
    assert run_upnp_description(root, scpd.replace(*edit)) == "refused"


def test_issue_15_a_long_request_name_of_an_argument_is_quoted_short(workspace: Workspace,
                                                                     taxonomy: Taxonomy) -> None:
    # seed 12: a request name of short words (too short for the long-word cut) was quoted whole
    text = GRIPPER.replace('pnp:request "Close"', 'pnp:request "Close' + " of {a: b}, {c: d}" * 30 + '"')
    path = workspace.write("devices/gripper.ttl", text.encode())
    with pytest.raises(DescriptionError) as info:
        load_device(path, taxonomy)
    assert "of request Close of {a: b}" in _one_line(info.value, text)


@pytest.mark.parametrize("key", ["? speed: 80", "? [speed, 80]\n      : 1", "{speed: 80}: 1"])
def test_issue_15_a_yaml_key_that_is_a_mapping_or_list_is_refused_at_its_line(workspace: Workspace,
                                                                              key: str) -> None:
    # seed 12: "? speed: 80" made a mapping a key; building the step's values raised "found unhashable key"
    text = dict(seeds("task"))["tasks/bin-picking.yaml"].decode().replace("speed: 80", key)
    path = workspace.write("tasks/bin-picking.yaml", text.encode())
    with pytest.raises(UnreadableError) as info:
        load_task(path)
    assert info.value.line == 15
    assert _one_line(info.value, text).endswith("a key is a list or a mapping; expected a plain name")
