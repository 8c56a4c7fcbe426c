"""A live view whose port is taken refuses the run before its run folder is made (issue 51, finding 10):
one line, nothing written, nothing left behind."""

import socket
import subprocess
import sys

import pytest

from graspexp.record.live import LiveViewError
from graspexp.run.job_config import compose_job
from graspexp.run.runner import run_in_dir

JOB = ["dataset=primitives", "objects=[mug]", "trials=1", "progress=false"]


@pytest.fixture
def taken_port():
    """A port on 127.0.0.1 that another program listens on."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        yield s.getsockname()[1]


def test_a_taken_live_port_refuses_the_run_before_its_folder_is_made(tmp_path, taken_port):
    cfg = compose_job([*JOB, "live=true", f"live_port={taken_port}"])
    with pytest.raises(LiveViewError, match=f"cannot listen on 127.0.0.1:{taken_port} .*pick a free port"):
        run_in_dir(cfg, tmp_path / "run")
    assert not (tmp_path / "run").exists()


def test_the_command_with_a_taken_live_port_is_one_line_and_leaves_no_folder(tmp_path, taken_port):
    run = tmp_path / "run"
    argv = [*JOB, "live=true", f"live_port={taken_port}", f"hydra.run.dir={run}"]
    done = subprocess.run(
        [sys.executable, "-m", "graspexp", *argv], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 2, done.stderr[-2000:]
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"graspexp: error: live view: cannot listen on 127.0.0.1:{taken_port} (")
    assert not run.exists()
