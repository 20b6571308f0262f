"""Nothing serialkin writes replaces a device, a pipe, a link or the input it reads."""

from __future__ import annotations

import os
import stat
import threading

import pytest
from click.testing import CliRunner

from serialkin._io import write_text_atomic
from serialkin.cli.main import cli
from serialkin.errors import OutputError


def test_a_device_is_written_through_not_replaced():
    """Writing to /dev/null leaves /dev/null a character device."""
    write_text_atomic("/dev/null", "x" * 1000)
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_a_fifo_is_written_through(tmp_path):
    """A named pipe receives the text and stays a pipe."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()))
    reader.start()
    write_text_atomic(fifo, "through the pipe")
    reader.join(timeout=10)
    assert got == ["through the pipe"]
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_a_link_is_followed_and_kept(tmp_path):
    """A symbolic link keeps being a link; the file it points to gets the text."""
    target = tmp_path / "real.txt"
    target.write_text("old")
    link = tmp_path / "link.txt"
    os.symlink(target, link)
    write_text_atomic(link, "new")
    assert os.path.islink(link) and target.read_text() == "new"
    dangling = tmp_path / "dangling.txt"
    os.symlink(tmp_path / "later.txt", dangling)
    write_text_atomic(dangling, "created")
    assert os.path.islink(dangling) and (tmp_path / "later.txt").read_text() == "created"


def test_a_folder_is_refused(tmp_path):
    """A folder as the output file is an OutputError, and the folder is untouched."""
    (tmp_path / "keep").write_text("k")
    with pytest.raises(OutputError, match="folder"):
        write_text_atomic(tmp_path, "x")
    assert (tmp_path / "keep").read_text() == "k"


@pytest.mark.parametrize("spell", ["same", "link", "dotted"])
def test_cli_refuses_an_output_that_is_an_input(tmp_path, spell):
    """--out naming the --q-file (directly, through a link, or spelled otherwise) is refused."""
    q = tmp_path / "q.csv"
    q.write_text("0,0\n0.1,0.2\n")
    out = {"same": q, "link": tmp_path / "alias.csv",
           "dotted": tmp_path / "." / ".." / tmp_path.name / "q.csv"}[spell]
    if spell == "link":
        os.symlink(q, out)
    res = CliRunner().invoke(cli, ["fk", "two_link", "--q-file", str(q), "--out", str(out)])
    assert res.exit_code == 2, res.output
    assert "would destroy the input" in res.output
    assert q.read_text() == "0,0\n0.1,0.2\n"


def test_cli_writes_json_to_a_device(tmp_path):
    """--out /dev/null works (JSON written through) and /dev/null stays a device."""
    res = CliRunner().invoke(cli, ["fk", "two_link", "--q", "0,0", "--out", "/dev/null"])
    assert res.exit_code == 0, res.output
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
