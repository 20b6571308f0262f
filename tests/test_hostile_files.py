"""Hostile files: every loader gives a correct result or one clear error of serialkin's types.

The promise (docs/files-safety.md): robot files, scenarios, URDF, trajectories and CSV
files either load correctly or raise a :class:`~serialkin.errors.SerialkinError` (the CLI:
one ``Error:`` line, exit 2) that names the file, within a time bound (a guard interrupts
a hang instead of timing the work), and nothing is half-written. Writers quote names with
the format's own library, so hostile names round-trip.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import serialkin as sk
from serialkin import _files
from serialkin._io import STALE_AFTER, remove_stale_temporaries, write_text_atomic
from serialkin.cli.io import CLIError, read_csv_rows
from serialkin.cli.main import cli
from serialkin.errors import RobotDefinitionError, SerialkinError
from serialkin.formats.robotfile import load_robot_file, robot_from_dict, save_robot_file
from serialkin.redundancy.obstacles import obstacle_from_dict
from serialkin.tracking import Trajectory, load_scenario, scenario_from_dict
from serialkin.tracking.scenario import ScenarioError

#: Generous bound for anything that must not hang (the alias bomb used to take > 10 s).
GUARD_S = 20.0

ROBOT = {"name": "two", "units": {"angle": "deg", "length": "m"},
         "dh": [{"a": 1.0, "alpha": 0, "d": 0, "theta": 0},
                {"a": 0.5, "alpha": 0, "d": 0, "theta": 0}]}
SCENARIO = {"robot": {"planar": {"links": 4, "length": 0.25}},
            "path": {"type": "circle", "center": [0.5, 0.0], "radius": 0.2}}

#: 545 bytes: nine levels of ten aliases, 10⁹ strings once expanded.
ALIAS_BOMB = "\n".join(
    ["a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    + [f"{c}: &{c} [{', '.join([f'*{p}'] * 10)}]" for p, c in zip("abcdefgh", "bcdefghi")]
) + "\n"


#: Characters an XML document can hold (XML 1.0 forbids most C0 controls).
_XML_OK_TEXT = st.characters(blacklist_categories=("Cs",), blacklist_characters="".join(
    map(chr, [*range(0, 9), 11, 12, *range(14, 32), 0xFFFE, 0xFFFF])))


@contextlib.contextmanager
def guard(seconds: float = GUARD_S) -> Iterator[None]:
    """Interrupt the block with TimeoutError if it runs longer than ``seconds`` (a hang)."""

    def _hang(signum, frame):  # noqa: ARG001
        raise TimeoutError(f"still running after {seconds} s")

    old = signal.signal(signal.SIGALRM, _hang)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def write(tmp_path: Path, name: str, content: str | bytes) -> Path:
    """Write a test file (text as UTF-8)."""
    p = tmp_path / name
    p.write_bytes(content.encode("utf-8") if isinstance(content, str) else content)
    return p


def fails(fn, *args, error: type[BaseException] = SerialkinError, **kwargs) -> str:
    """Run ``fn`` under the guard; it must raise ``error``; return the message."""
    with guard(), pytest.raises(error) as info:
        fn(*args, **kwargs)
    return str(info.value)


# ----------------------------------------------------------------------- parsing limits
def test_alias_bomb_fails_fast_in_robot_files_and_scenarios(tmp_path):
    """A 545-byte YAML alias bomb is refused (bounded expansion) as a robot file and a scenario."""
    assert len(ALIAS_BOMB) <= 545
    robot = write(tmp_path, "bomb.yaml", "name: x\nunits: {angle: deg}\n" + ALIAS_BOMB)
    msg = fails(load_robot_file, robot, error=RobotDefinitionError)
    assert "bomb.yaml" in msg and "alias" in msg
    scen = write(tmp_path, "bomb_scenario.yaml", ALIAS_BOMB)
    msg = fails(load_scenario, scen, error=ScenarioError)
    assert "bomb_scenario.yaml" in msg and "aliases are expanded" in msg


def test_alias_bomb_cli_exits_2_without_hanging(tmp_path):
    """`serialkin fk bomb.yaml` and `track bomb.yaml` end quickly with one Error line, exit 2."""
    bomb = write(tmp_path, "bomb.yaml", ALIAS_BOMB)
    for args in (["fk", str(bomb), "--q", "0"], ["track", str(bomb)]):
        proc = subprocess.run([sys.executable, "-m", "serialkin.cli.main", *args],
                              capture_output=True, text=True, timeout=120,
                              env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
        assert proc.returncode == 2, (args, proc.stderr)
        assert proc.stderr.startswith("Error:") and "Traceback" not in proc.stderr


def test_aliases_within_bounds_still_work(tmp_path):
    """Ordinary anchors and aliases (a shared joint range) and merge keys still load."""
    doc = ("name: aliased\nunits: {angle: deg}\ndh:\n"
           "  - &row {a: 1, alpha: 0, d: 0, theta: 0, qlim: &lim [-90, 90]}\n"
           "  - {<<: *row, a: 0.5, qlim: *lim, name: elbow}\n")
    r = load_robot_file(write(tmp_path, "aliased.yaml", doc))
    assert r.n == 2 and r.joint_names == ("joint1", "elbow")
    assert np.allclose(r.qlim, np.radians([[-90, 90], [-90, 90]]))
    assert np.allclose(r.fk([0, 0])[:3, 3], [1.5, 0, 0])


def test_recursive_alias_is_refused():
    """An alias to an enclosing anchor (a self-containing list) is refused, not built."""
    msg = fails(_files.parse_yaml, "a: &x [1, *x]\n", "r.yaml")
    assert "r.yaml" in msg and "recursive" in msg


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_duplicate_keys_are_refused(tmp_path, suffix):
    """`links: 3 ... links: 4` and a repeated robot-file key are errors, not 'last one wins'."""
    if suffix == ".yaml":
        scen = ("robot:\n  planar:\n    links: 3\n    length: 0.25\n    links: 4\n"
                "path: {type: circle, center: [0.5, 0], radius: 0.2}\n")
        robot = "name: a\nunits: {angle: deg}\nname: b\ndh: [{a: 1, alpha: 0, d: 0, theta: 0}]\n"
    else:
        scen = ('{"robot": {"planar": {"links": 3, "length": 0.25, "links": 4}}, '
                '"path": {"type": "circle", "center": [0.5, 0], "radius": 0.2}}')
        robot = json.dumps(ROBOT)[:-1] + ', "name": "b"}'
    msg = fails(load_scenario, write(tmp_path, "dup" + suffix, scen), error=ScenarioError)
    assert "duplicate key 'links'" in msg and "dup" + suffix in msg
    msg = fails(load_robot_file, write(tmp_path, "dup_robot" + suffix, robot),
                error=RobotDefinitionError)
    assert "duplicate key 'name'" in msg


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_deep_nesting_is_refused(tmp_path, suffix):
    """Nesting 100 000 levels deep gives a clear error, never a RecursionError."""
    deep = "[" * 100_000 + "]" * 100_000
    text = f"name: x\nunits: {deep}\n" if suffix == ".yaml" else f'{{"units": {deep}}}'
    msg = fails(load_robot_file, write(tmp_path, "deep" + suffix, text),
                error=RobotDefinitionError)
    assert "deep" + suffix in msg and ("nesting" in msg or "depth" in msg)


def test_size_limit_and_non_files(tmp_path):
    """Too large, a folder, missing and non-UTF-8 files are refused by name before parsing."""
    big = write(tmp_path, "big.yaml", "x" * 2000)
    assert "more than the limit of 1000 bytes" in fails(_files.read_bytes, big, max_bytes=1000)
    folder = tmp_path / "folder.yaml"
    folder.mkdir()
    assert "is a folder" in fails(load_robot_file, folder)
    assert "is a folder" in fails(load_scenario, folder)
    assert "not found" in fails(load_robot_file, tmp_path / "missing.yaml")
    latin = write(tmp_path, "latin.yaml", "name: caf\xe9\n".encode("latin-1"))
    assert "not UTF-8" in fails(load_robot_file, latin)
    assert "not UTF-8" in fails(load_scenario, write(tmp_path, "s.yaml", b"robot: \xff\n"))
    assert "got int 5" in fails(load_scenario, 5)
    assert "got NoneType None" in fails(load_robot_file, None)


def test_yaml_tags_never_execute(tmp_path):
    """A python/object tag is a parse error; nothing is imported or called."""
    text = "name: !!python/object/apply:os.system ['echo hacked']\nunits: {angle: deg}\n"
    assert "invalid YAML" in fails(load_robot_file, write(tmp_path, "tag.yaml", text))


# ----------------------------------------------------------------------- field reading
ROBOT_CASES = [
    (lambda d: d.__setitem__("units", {"angle": ["deg"]}), "units.angle"),
    (lambda d: d["dh"][0].__setitem__("a", 10**400), "dh[0].a"),
    (lambda d: d["dh"][0].__setitem__("a", 1e308), "dh[0].a"),
    (lambda d: d["dh"][1].__setitem__("d", -1e300), "dh[1].d"),
    (lambda d: d["dh"][0].__setitem__("qlim", [math.inf, math.inf]), "dh[0].qlim[0]"),
    (lambda d: d["dh"][0].__setitem__("qlim", "12"), "dh[0].qlim"),
    (lambda d: d["dh"][0].__setitem__("type", ["R"]), "dh[0].type"),
    (lambda d: d["dh"][0].__setitem__("name", {"x": 1}), "dh[0].name"),
    (lambda d: d.__setitem__("name", ["arm"]), "'name'"),
    (lambda d: d.__setitem__(1, 2), "not a text name"),
    (lambda d: d.__setitem__("dh", [{"a": 1}] * 20_000), "dh"),
    (lambda d: d.__setitem__("tool", {"xyz": [10**400, 0, 0]}), "tool.xyz[0]"),
]


@pytest.mark.parametrize(("mutate", "needle"), ROBOT_CASES)
def test_robot_file_fields_checked_before_use(mutate, needle):
    """Unhashable, huge, wrongly typed values in a robot file give one RobotDefinitionError."""
    doc = json.loads(json.dumps(ROBOT))
    mutate(doc)
    msg = fails(robot_from_dict, doc, "arm.yaml", error=RobotDefinitionError)
    assert "arm.yaml" in msg and needle in msg
    assert len(msg) < 600


SCENARIO_CASES = [
    (lambda d: d.__setitem__("robot", {"model": "dataclass"}), "robot.model"),
    (lambda d: d.__setitem__("robot", {"model": ["ur5"]}), "robot.model"),
    (lambda d: d["path"].__setitem__("type", ["circle"]), "path.type"),
    (lambda d: d.__setitem__(1, 2), "not a text name"),
    (lambda d: d.__setitem__("solver", {"method": "lm", "options": {1: 2}}), "solver.options"),
    (lambda d: d.__setitem__("solver", {"method": "lm", "options": {"bogus": 2}}),
     "solver.options.bogus"),
    (lambda d: d.__setitem__("solver", {"max_iter": 1e30}), "solver.max_iter"),
    (lambda d: d.__setitem__("solver", {"max_iter": 2**64}), "solver.max_iter"),
    (lambda d: d["robot"]["planar"].__setitem__("length", 1e308), "robot.planar.length"),
    (lambda d: d["robot"]["planar"].__setitem__("links", 1e8), "robot.planar.links"),
    (lambda d: d["robot"]["planar"].__setitem__("links", 10**8), "robot.planar.links"),
    (lambda d: d.__setitem__("robot", {"dh": [{"a": 1e308, "alpha": 0, "d": 0, "theta": 0}]}),
     "robot.dh[0].a"),
    (lambda d: d["path"].__setitem__("step", 1e-9), "path.step"),
    (lambda d: d.__setitem__("obstacles", [{"type": "circle", "center": [0.5, "x"],
                                            "radius": 0.1}]), "obstacles[0].center[1]"),
    (lambda d: d.__setitem__("q0", [[0.0] * 4]), "q0"),
]


@pytest.mark.parametrize(("mutate", "needle"), SCENARIO_CASES)
def test_scenario_fields_checked_before_use(mutate, needle):
    """Each hostile scenario field gives one ScenarioError naming the file and the field."""
    doc = json.loads(json.dumps(SCENARIO))
    mutate(doc)
    msg = fails(scenario_from_dict, doc, "hostile.json", error=ScenarioError)
    assert "hostile.json" in msg and needle in msg
    assert len(msg) < 800


def test_links_out_of_range_message():
    """The message of `planar: {links: 1e8}` states the field, the range and the value."""
    doc = json.loads(json.dumps(SCENARIO))
    doc["robot"]["planar"]["links"] = 1e8
    msg = fails(scenario_from_dict, doc, "s.json")
    assert "field 'robot.planar.links' must be an integer in [1, 10000], got 100000000.0" in msg


# ----------------------------------------------------------------------- fuzzing
_scalars = (st.none() | st.booleans() | st.integers() | st.integers(min_value=10**30)
            | st.floats() | st.text(max_size=12)
            | st.sampled_from(["R", "P", "deg", "rad", "circle", "q0", "dls", "lm", "planar"]))
_json = st.recursive(_scalars, lambda kids: st.lists(kids, max_size=4)
                     | st.dictionaries(st.text(max_size=8) | st.integers(), kids, max_size=4),
                     max_leaves=20)


def _paths(doc: object, prefix: tuple = ()) -> list[tuple]:
    """Every key path of a nested dict/list document."""
    out = [prefix]
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            out += _paths(v, (*prefix, i))
    return out


def _replace(doc: object, path: tuple, value: object) -> object:
    if not path:
        return value
    doc = json.loads(json.dumps(doc))
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return doc


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), junk=_json)
def test_fuzz_robot_files_field_by_field(data, junk):
    """Any field of a valid robot file replaced by junk: a robot or a RobotDefinitionError."""
    path = data.draw(st.sampled_from(_paths(ROBOT)))
    with guard():
        try:
            r = robot_from_dict(_replace(ROBOT, path, junk), "fuzz.yaml")
        except RobotDefinitionError as exc:
            assert "fuzz.yaml" in str(exc)
            return
    assert np.isfinite(r.fk(np.zeros(r.n))).all()


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), junk=_json)
def test_fuzz_scenarios_field_by_field(data, junk):
    """Any field of a valid scenario replaced by junk: a scenario or a ScenarioError."""
    path = data.draw(st.sampled_from(_paths(SCENARIO)))
    with guard():
        try:
            sc = scenario_from_dict(_replace(SCENARIO, path, junk), "fuzz.yaml")
        except ScenarioError as exc:
            assert "fuzz.yaml" in str(exc)
            return
    assert sc.robot.n >= 1 and len(sc.path) >= 1


@settings(max_examples=60, deadline=None)
@given(doc=_json)
def test_fuzz_whole_documents(doc):
    """Arbitrary documents as robot file, scenario or obstacle: a result or a library error."""
    for fn in (robot_from_dict, scenario_from_dict, obstacle_from_dict):
        with guard():
            try:
                fn(doc)
            except SerialkinError as exc:
                assert len(str(exc)) < 1000


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                 HealthCheck.function_scoped_fixture])
@given(blob=st.binary(max_size=300) | st.text(max_size=300).map(str.encode))
def test_fuzz_raw_bytes_into_every_loader(tmp_path, blob):
    """Random bytes as robot file, scenario, URDF, trajectory and CSV: only library errors."""
    loaders = [("r.yaml", load_robot_file), ("r.json", load_robot_file),
               ("s.yaml", load_scenario), ("u.urdf", sk.Robot.from_urdf),
               ("t.csv", Trajectory.load), ("t.npz", Trajectory.load),
               ("q.csv", lambda p: read_csv_rows(p, "q", 2))]
    for name, fn in loaders:
        p = write(tmp_path, name, blob)
        with guard():
            try:
                fn(p)
            except (SerialkinError, CLIError):
                pass


# ----------------------------------------------------------------------- URDF
_URDF_SLOTS = ("robot.name", "link.name", "joint.name", "joint.type", "parent.link",
               "child.link", "origin.xyz", "origin.rpy", "axis.xyz", "limit.lower",
               "limit.upper")


@settings(max_examples=60, deadline=None)
@given(slot=st.sampled_from(_URDF_SLOTS),
       value=st.text(alphabet=_XML_OK_TEXT, max_size=30)
       | st.lists(st.floats() | st.integers(), max_size=4).map(
           lambda v: " ".join(map(str, v))))
def test_fuzz_urdf_attributes(slot, value):
    """Any attribute of a valid URDF replaced by junk: a robot or a library error."""
    root = ET.fromstring(
        "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
        "<parent link='a'/><child link='b'/><origin xyz='0 0 0.1' rpy='0 0 0'/>"
        "<axis xyz='0 0 1'/><limit lower='-1' upper='1'/></joint></robot>")
    tag, attr = slot.split(".")
    el = root if tag == "robot" else root.find(f".//{tag}")
    el.set(attr, value)
    with guard():
        try:
            r = sk.Robot.from_urdf(ET.tostring(root, encoding="unicode"))
        except SerialkinError:
            return
    assert np.isfinite(r.fk(np.zeros(r.n))).all()


def test_urdf_declared_latin1_encoding_loads(tmp_path):
    """A URDF declaring encoding="ISO-8859-1" (valid XML) loads with its names decoded."""
    text = ('<?xml version="1.0" encoding="ISO-8859-1"?>\n<robot name="caf\xe9">'
            '<link name="a"/><link name="b"/><joint name="gel\xe9nk" type="revolute">'
            '<parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint></robot>')
    r = sk.Robot.from_urdf(str(write(tmp_path, "latin.urdf", text.encode("latin-1"))))
    assert r.name == "café" and r.joint_names == ("gelénk",)


def test_urdf_loop_off_the_chain_is_refused():
    """Links c <-> d joined in a loop beside the chain a -> b make the URDF invalid."""
    text = ("<robot name='x'><link name='a'/><link name='b'/><link name='c'/><link name='d'/>"
            "<joint name='j1' type='revolute'><parent link='a'/><child link='b'/></joint>"
            "<joint name='j2' type='fixed'><parent link='c'/><child link='d'/></joint>"
            "<joint name='j3' type='fixed'><parent link='d'/><child link='c'/></joint></robot>")
    msg = fails(sk.Robot.from_urdf, text, error=RobotDefinitionError)
    assert "loop" in msg and "c, d" in msg


def test_urdf_external_entities_and_entity_bombs_are_refused(tmp_path):
    """XXE (a SYSTEM entity) and an exponential entity bomb give RobotDefinitionError."""
    secret = write(tmp_path, "secret.txt", "TOPSECRET")
    xxe = (f'<?xml version="1.0"?><!DOCTYPE robot [<!ENTITY x SYSTEM "file://{secret}">]>'
           '<robot name="&x;"><link name="a"/></robot>')
    msg = fails(sk.Robot.from_urdf, xxe, error=RobotDefinitionError)
    assert "TOPSECRET" not in msg
    ents = ['<!ENTITY e0 "lol">'] + [f'<!ENTITY e{i} "{f"&e{i - 1};" * 10}">'
                                     for i in range(1, 10)]
    bomb = f'<?xml version="1.0"?><!DOCTYPE robot [{"".join(ents)}]><robot name="&e9;"/>'
    fails(sk.Robot.from_urdf, bomb, error=RobotDefinitionError)


def test_urdf_names_with_markup_round_trip():
    """`R&D <arm>`, `j"1` and markup in joint names are escaped: same names, same FK."""
    r = sk.Robot.from_dh([{"a": 0.5, "alpha": 0.3, "d": 0.1, "theta": 0.0, "name": 'j"1'},
                          {"a": 0.3, "alpha": 0, "d": 0, "theta": 0,
                           "name": '"/><joint name="evil" type="fixed">'}], name="R&D <arm>")
    text = r.to_urdf()
    assert len(ET.fromstring(text).findall("joint")) == 3  # two joints and the tool: none injected
    r2 = sk.Robot.from_urdf(text)
    assert r2.name == "R&D <arm>" and r2.joint_names == r.joint_names
    assert np.allclose(r2.fk([0.2, -0.4]), r.fk([0.2, -0.4]))


def test_urdf_refuses_names_xml_cannot_hold():
    """A control character XML 1.0 forbids in a name is a clear error, not a broken file."""
    r = sk.Robot.from_dh([{"a": 1, "alpha": 0, "d": 0, "theta": 0, "name": "a\x01b"}])
    assert "U+0001" in fails(r.to_urdf, error=RobotDefinitionError)


# ----------------------------------------------------------------------- writers
_names = st.text(alphabet=_XML_OK_TEXT | st.sampled_from(list("\n\"'<>&:#{}[]- ")), min_size=1,
                 max_size=16).filter(lambda s: s.strip() != "")


@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(name=_names, j1=_names, j2=_names)
def test_hostile_names_round_trip_in_yaml_json_and_urdf(tmp_path, name, j1, j2):
    """Robots with hostile names save and reload in YAML, JSON and URDF with equal names and FK."""
    j2 = j2 if j2 != j1 else j2 + "_2"
    r = sk.Robot.from_dh([{"a": 0.4, "alpha": 0.5, "d": 0.1, "theta": 0.2, "name": j1},
                          {"a": 0.3, "alpha": 0.0, "d": 0.0, "theta": 0.0, "name": j2,
                           "qlim": (-1.0, 2.0)}], name=name, tool=np.eye(4))
    q = np.array([0.3, -0.7])
    for suffix in (".yaml", ".json"):
        r2 = load_robot_file(save_robot_file(r, tmp_path / f"hostile{suffix}"))
        assert r2.name == name and r2.joint_names == (j1, j2)
        assert np.allclose(r2.fk(q), r.fk(q), atol=1e-9)
    r3 = sk.Robot.from_urdf(r.to_urdf())
    assert r3.name == name and r3.joint_names == (j1, j2)
    assert np.allclose(r3.fk(q), r.fk(q), atol=1e-9)


def test_name_cannot_rewrite_a_saved_file_via_cli(tmp_path):
    """`models in.yaml --save out.yaml` keeps a name holding a YAML line as a name."""
    doc = json.loads(json.dumps(ROBOT))
    doc["name"] = "arm\ntool: {xyz: [5,0,0]}"
    src = write(tmp_path, "in.json", json.dumps(doc))
    out = tmp_path / "out.yaml"
    res = CliRunner().invoke(cli, ["models", str(src), "--save", str(out)])
    assert res.exit_code == 0, res.output
    a, b = load_robot_file(src), load_robot_file(out)
    assert b.name == doc["name"] and np.allclose(b.tool, np.eye(4))
    assert np.allclose(a.fk([0.1, 0.2]), b.fk([0.1, 0.2]))


# ----------------------------------------------------------------------- stale temporaries
def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_kill_9_leftover_is_removed_by_the_next_write(tmp_path):
    """A writer killed by SIGKILL before its rename leaves a .tmp; the next write removes it."""
    target = tmp_path / "out.txt"
    code = ("import os, sys, time\nfrom serialkin import _io\n"
            "os.replace = lambda a, b: (print('ready', flush=True), time.sleep(600))\n"
            f"_io.write_text_atomic({str(target)!r}, 'x' * 1000)\n")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    try:
        assert proc.stdout.readline().strip() == "ready"
    finally:
        proc.kill()
        proc.wait()
    left = [p.name for p in tmp_path.iterdir()]
    assert len(left) == 1 and left[0].startswith(".out.txt.") and left[0].endswith(".tmp")
    write_text_atomic(target, "new")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]
    assert target.read_text() == "new"


def test_running_writers_temporaries_are_kept(tmp_path):
    """Temporaries of a live process, of this process and fresh old-style ones stay; stale go."""
    from serialkin._io import _host_tag

    target = tmp_path / "t.json"
    me = _host_tag()
    live = tmp_path / f".t.json.{me}-{os.getppid()}.abcdefgh.tmp"
    mine = tmp_path / f".t.json.{me}-{os.getpid()}.abcdefgh.tmp"
    dead = tmp_path / f".t.json.{me}-{_dead_pid()}.abcdefgh.tmp"
    other_host = tmp_path / ".t.json.00000000-1.abcdefgh.tmp"
    old_fresh = tmp_path / ".t.json.abcdefgh.tmp"
    old_stale = tmp_path / ".t.json.zyxwvuts.tmp"
    unrelated = tmp_path / ".t.json.backup.tmp"
    for p in (live, mine, dead, other_host, old_fresh, old_stale, unrelated):
        p.write_text("partial")
    past = time.time() - STALE_AFTER - 10
    os.utime(old_stale, (past, past))
    removed = remove_stale_temporaries(target)
    assert sorted(removed) == sorted([dead, old_stale])
    assert all(p.exists() for p in (live, mine, other_host, old_fresh, unrelated))
    later = time.time() + STALE_AFTER + 10
    assert set(remove_stale_temporaries(target, now=later)) == {live, mine, other_host,
                                                                  old_fresh}
    assert unrelated.exists()


# ----------------------------------------------------------------------- trajectories
@pytest.fixture(scope="module")
def trajectory(tmp_path_factory) -> tuple[Path, Trajectory]:
    """A tracked trajectory saved as CSV and NPZ in a temporary folder."""
    folder = tmp_path_factory.mktemp("traj")
    t = load_scenario("six_link_circle").run()
    t.save(folder / "ok.csv")
    t.save(folder / "ok.npz")
    return folder, t


def _corrupt_trajectories(folder: Path) -> dict[str, Path]:
    csv_text = (folder / "ok.csv").read_text()
    out = {
        "bad JSON header": write(folder, "hdr.csv", csv_text.replace("trajectory {",
                                                                      "trajectory {{", 1)),
        "text rows": write(folder, "text.csv", csv_text.replace("\n0,", "\nzero,", 1)),
        "non-zip npz": write(folder, "nonzip.npz", b"PK\x03\x04 this is no zip file"),
        "short row": write(folder, "short.csv", csv_text + "1,2\n"),
    }
    with np.load(folder / "ok.npz") as z:
        arrays = dict(z)
    arrays["q"] = np.array([[object()] * 6], dtype=object)
    np.savez(folder / "pickled.npz", **arrays)
    out["pickled npz"] = folder / "pickled.npz"
    return out


def test_trajectory_files_round_trip(trajectory):
    """Saved CSV and NPZ trajectories load back with the same joint values and failures."""
    folder, t = trajectory
    for name in ("ok.csv", "ok.npz"):
        t2 = Trajectory.load(folder / name)
        assert np.allclose(t2.q, t.q) and t2.failures == t.failures and t2.task == t.task


def test_corrupt_trajectories_give_one_library_error(trajectory):
    """Bad JSON header, text rows, a non-zip or pickled .npz: one InputError naming the file."""
    folder, _ = trajectory
    for what, p in _corrupt_trajectories(folder).items():
        msg = fails(Trajectory.load, p)
        assert p.name in msg, what


def test_view_with_corrupt_trajectory_exits_2_and_writes_nothing(trajectory, tmp_path):
    """`serialkin view --trajectory <corrupt>` prints one Error line, exits 2, writes no page."""
    folder, _ = trajectory
    for what, p in _corrupt_trajectories(folder).items():
        out = tmp_path / f"{p.stem}.html"
        res = CliRunner().invoke(cli, ["view", "planar6", "--trajectory", str(p),
                                       "--out", str(out)])
        assert res.exit_code == 2, (what, res.output)
        assert "Error:" in res.output and "Traceback" not in res.output
        assert not out.exists(), what


def test_csv_rows_reader_hostile_cells(tmp_path):
    """A CSV with a huge cell, inf or a NUL byte is a one-line CLIError with a bounded message."""
    cases = {"huge.csv": "0," + "9" * 100_000 + "x\n", "inf.csv": "0,1e999\n",
             "nul.csv": "0,\x001\n"}
    for name, text in cases.items():
        msg = fails(read_csv_rows, write(tmp_path, name, text), "q", 2, error=CLIError)
        assert name in msg and len(msg) < 400
    folder = tmp_path / "dir.csv"
    folder.mkdir()
    assert "folder" in fails(read_csv_rows, folder, "q", 2, error=CLIError)
