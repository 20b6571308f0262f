"""A xacro file is data: no code runs, no file outside is read, and the work is bounded."""

from __future__ import annotations

import math
import os
import tracemalloc

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from serialkin import Robot
from serialkin.errors import BudgetError, RobotDefinitionError
from serialkin.formats.xacro_expr import XacroExpressionError, evaluate

pytest.importorskip("xacro", reason="the xacro extra is not installed")

HEAD = "<robot name='r' xmlns:xacro='http://www.ros.org/wiki/xacro'>"
ARM = ("<link name='base'/><link name='tip'/>"
       "<joint name='j' type='revolute'><parent link='base'/><child link='tip'/>"
       "<origin xyz='{x} 0 0'/><axis xyz='0 0 1'/>"
       "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint>")


def _doc(body: str) -> str:
    return f"{HEAD}{body}</robot>"


def _names(table: dict):
    def lookup(name):
        return table[name]
    return lookup


ESCAPES = [
    "().__class__.__bases__[0].__subclasses__()",
    "[c for c in ().__class__.__mro__]",
    "(lambda: 1)()",
    "open('/etc/passwd').read()",
    "__import__('os').system('true')",
    "python.type(1)",
    "type(1)",
    "xacro.abs_filename('x')",
    "getattr(1, 'real')",
    "exec('x = 1')",
    "eval('1')",
    "{'a': 1}.keys()",
    "'abc'.upper()",
    "(x := 1)",
    "f'{1}'",
    "min(*[1, 2])",
    "round(1.5, ndigits=0)",
    "sin",
    "dict",
    "vars()",
]


@pytest.mark.parametrize("expression", ESCAPES)
def test_expressions_that_reach_python_are_refused(expression):
    """Attributes, calls outside the table, lambda, comprehensions, walrus, f-strings: refused."""
    with pytest.raises(XacroExpressionError):
        evaluate(expression, _names({}))


@pytest.mark.parametrize("expression, expected", [
    ("pi / 2", math.pi / 2),
    ("math.pi", math.pi),
    ("radians(90)", math.pi / 2),
    ("math.cos(0) + sqrt(4)", 3.0),
    ("a * 2 if flag else 3", 8),
    ("not flag or a > 3", True),
    ("-a ** 2", -16),
    ("1 < a <= 4", True),
    ("'link_' + str(a)", "link_4"),
    ("cfg['len'][1]", 0.5),
    ("cfg.len[0]", 0.25),
    ("max(a, 7) // 2", 3),
    ("[a, 1.5][1]", 1.5),
    ("'x' in 'xyz'", True),
])
def test_what_robot_files_use_still_evaluates(expression, expected):
    """Numbers, names, arithmetic, comparisons, conditionals, math and data items evaluate."""
    table = {"a": 4, "flag": True, "cfg": {"len": [0.25, 0.5]}}
    assert evaluate(expression, _names(table)) == expected


@pytest.mark.parametrize("expression", ["9**9**9**9", "2**100000", "'a' * 10**9",
                                        "[0] * 10**8", "10**4000 * 10**4000",
                                        "1" + "+1" * 20000])
def test_expressions_beyond_their_budget_stop_at_once(expression):
    """Huge integers, strings, lists or expressions raise BudgetError before being computed."""
    tracemalloc.start()  # the work done, measured as memory: refused before computing
    with pytest.raises(BudgetError):
        evaluate(expression, _names({}))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 4 * 2**20, f"{peak} bytes allocated before the refusal"


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet="abcdefxyz0123456789_.()[]{}'\"+-*/%<>=!&|^~:,@ \\lambdaforin",
               max_size=60))
def test_any_text_is_data_or_a_clear_error(text):
    """Any expression text evaluates to data or raises XacroExpressionError / BudgetError."""
    try:
        value = evaluate(text, _names({"a": 1, "x": 2.0, "f": [1, 2]}))
    except (XacroExpressionError, BudgetError):
        return
    assert value is None or isinstance(value, bool | int | float | str | list | tuple | dict)


def test_a_file_cannot_run_code_or_read_files(tmp_path):
    """Code or file reads in ${}, $(eval) (a property closing the call) and YAML are refused."""
    marker = tmp_path / "ran"
    attempts = [
        f"<link name='${{open(\"{marker}\", \"w\")}}'/>",
        "<link name='$(eval open(\"/etc/passwd\").read())'/>",
        f"<xacro:property name='close' value=')'/>"
        f"<link name='$(eval exec(\"open(\\'{marker}\\', \\'w\\')\"${{close}}'/>",
        "<link name='${().__class__.__base__.__subclasses__()}'/>",
        "<link name='${xacro.load_yaml(\"/etc/passwd\")}'/>",
    ]
    for body in attempts:
        with pytest.raises(RobotDefinitionError):
            Robot.from_xacro(_doc(body))
    assert not marker.exists()


def test_the_error_names_file_line_and_expression(tmp_path):
    """A refused expression in a file names the file, its line and the expression."""
    f = tmp_path / "arm.xacro"
    f.write_text(_doc("\n\n<link name='${(lambda: 0)()}'/>" + ARM.format(x=1)))
    with pytest.raises(XacroExpressionError, match=r"arm\.xacro: line 3: expression "
                                                   r"'\(lambda: 0\)\(\)': lambda"):
        Robot.from_xacro(f)


def test_includes_and_yaml_stay_inside_the_allowed_folders(tmp_path):
    """Includes and load_yaml inside the file's folder work; .., absolute paths, links don't."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "part.xacro").write_text(_doc(ARM.format(x="${L}")))
    (pkg / "dims.yaml").write_text("L: 0.4\n")
    good = pkg / "good.xacro"
    good.write_text(_doc("<xacro:property name='d' value='${xacro.load_yaml(\"dims.yaml\")}'/>"
                         "<xacro:property name='L' value='${d[\"L\"]}'/>"
                         "<xacro:include filename='part.xacro'/>"))
    robot = Robot.from_xacro(good)
    assert robot.n == 1 and abs(robot.fk([0.0])[0, 3] - 0.4) < 1e-12

    (tmp_path / "secret.yaml").write_text("L: 9\n")
    os.symlink(tmp_path / "secret.yaml", pkg / "link.yaml")
    for body in ["<xacro:include filename='../secret.yaml'/>",
                 "<xacro:include filename='/etc/passwd'/>",
                 "<xacro:property name='d' value='${load_yaml(\"../secret.yaml\")}'/>"
                 "<link name='${d[\"L\"]}'/>",
                 "<xacro:property name='d' value='${load_yaml(\"link.yaml\")}'/>"
                 "<link name='${d[\"L\"]}'/>",
                 "<link name='$(find ..)'/>",
                 "<link name='$(find ../../etc)'/>"]:
        bad = pkg / "bad.xacro"
        bad.write_text(_doc(body))
        with pytest.raises(RobotDefinitionError, match="outside the folders|not a package name"):
            Robot.from_xacro(bad, search_path=[pkg])


def test_exponential_macros_hit_the_budget(monkeypatch):
    """A macro that calls itself twice per level, 40 levels deep, raises BudgetError.

    At the budget, not after 2⁴¹ calls: lowered here to 2,000 calls (the default,
    MAX_MACRO_CALLS = 50,000, takes about 9 s of expansion to reach).
    """
    from serialkin.formats import xacro

    monkeypatch.setattr(xacro, "MAX_MACRO_CALLS", 2_000)
    body = ("<xacro:macro name='m' params='n'><xacro:if value='${n > 0}'>"
            "<xacro:m n='${n - 1}'/><xacro:m n='${n - 1}'/></xacro:if></xacro:macro>"
            "<xacro:m n='40'/>")
    with pytest.raises(BudgetError, match="macro calls") as err:
        Robot.from_xacro(_doc(body))
    # bounded work: the call counter stopped it (not the 2⁴¹ calls the file asks for)
    assert "more than 2000 macro calls" in str(err.value), str(err.value)


def test_a_path_longer_than_the_system_allows_is_named():
    """A xacro path of 5,000 characters raises RobotDefinitionError, shortened, not OSError."""
    with pytest.raises(RobotDefinitionError) as info:
        Robot.from_xacro("/tmp/" + "a" * 5000 + ".xacro")
    assert len(str(info.value)) < 400
