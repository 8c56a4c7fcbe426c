"""Hydra entry point: ``python -m graspexp [group=option ...]`` (or the ``graspexp`` command) runs trials
for every object; the command line is parsed and checked first by :func:`graspexp.cli.run_checked`."""

import hydra
from omegaconf import DictConfig

from graspexp.cli import run_checked
from graspexp.config import register_configs
from graspexp.config.registry import CONF_DIR
from graspexp.jobs import job_failed

register_configs()


@hydra.main(
    version_base="1.3", config_path=CONF_DIR, config_name="config"
)  # absolute: also for the console script
def _job(cfg: DictConfig) -> float | None:
    from graspexp.datasets import DatasetError
    from graspexp.record.live import LiveViewError
    from graspexp.runner import RunError, run_job

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


def main() -> None:
    """Console-script entry (``graspexp``)."""
    run_checked(_job)


if __name__ == "__main__":
    main()
