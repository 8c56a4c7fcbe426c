"""Hydra entry point: ``python -m graspexp [group=option ...]`` runs trials for every object."""

import hydra
from omegaconf import DictConfig

from graspexp.cli import fail, run_checked
from graspexp.config import register_configs

register_configs()


@hydra.main(version_base="1.3", config_path="../conf", config_name="config")
def _job(cfg: DictConfig) -> float:
    from graspexp.datasets import DatasetError
    from graspexp.record.live import LiveViewError
    from graspexp.runner import run_job

    try:
        return run_job(cfg)
    except (DatasetError, LiveViewError) as exc:
        fail(str(exc))


def main() -> None:
    """Console-script entry (``graspexp``)."""
    run_checked(_job)


if __name__ == "__main__":
    main()
