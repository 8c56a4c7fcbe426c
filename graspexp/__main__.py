"""Entry point: ``python -m graspexp [group=option ...]`` (or the ``graspexp`` command) runs trials for
every object (the Hydra app; the command line is parsed and checked first by
:func:`graspexp.tools.cli.run_checked`); ``python -m graspexp TOOL [...]`` runs one of
:data:`graspexp.tools.TOOLS`."""

import importlib
import logging
import sys
from collections.abc import Sequence

import hydra
from omegaconf import DictConfig

from graspexp.config import register_configs
from graspexp.config.registry import CONF_DIR
from graspexp.run.jobs import job_failed
from graspexp.tools import TOOLS
from graspexp.tools.cli import run_checked

register_configs()


@hydra.main(
    version_base="1.3", config_path=CONF_DIR, config_name="config"
)  # absolute: also for the console script
def _job(cfg: DictConfig) -> float | None:
    # a log handler that cannot write (Hydra's job log on a full disk, a removed or read-only run directory)
    # drops the message instead of printing logging's own traceback: the job's one error line says what failed
    logging.raiseExceptions = False
    from graspexp.datasets import DatasetError
    from graspexp.record.live import LiveViewError
    from graspexp.run.locks import RunError
    from graspexp.run.runner import run_job

    try:
        return run_job(cfg)
    except (
        DatasetError,
        RunError,
        LiveViewError,
    ) as exc:  # this job cannot run; in a multirun, the others go on
        job_failed(str(exc))
    except OSError as exc:  # an input or output file: one line, not a traceback
        job_failed(f"{exc.strerror or exc}: {exc.filename}" if exc.filename else str(exc))
    return None


def main(argv: Sequence[str] | None = None) -> None:
    """Console-script entry (``graspexp``): a tool when the first word names one, else a job."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in TOOLS:
        tool = importlib.import_module(f"graspexp.tools.{argv[0]}")
        raise SystemExit(tool.main(argv[1:]) or 0)
    run_checked(_job)


if __name__ == "__main__":
    main()
