"""The run stage: runs the trials of a job (runner), the jobs of a sweep (jobs, Hydra's launchers), the
paper's and the project's job matrices (suites), and re-simulates a logged trial (resim). It drives every
stage below it: config -> datasets -> planning -> sim -> record -> report."""
