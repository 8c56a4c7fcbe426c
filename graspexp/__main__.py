"""Hydra entry point: ``python -m graspexp [group=option ...]`` runs trials for every object."""

import hydra
from omegaconf import DictConfig

from graspexp.config import register_configs

register_configs()


@hydra.main(version_base="1.3", config_path="../conf", config_name="config")
def _job(cfg: DictConfig) -> float:
    from graspexp.runner import run_job

    return run_job(cfg)


def main() -> None:
    """Console-script entry (``graspexp``)."""
    _job()


if __name__ == "__main__":
    main()
