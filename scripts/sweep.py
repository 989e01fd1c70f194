"""Design studies with TLD.fmu on dask.distributed (python/tld_fmu/study.py):

    .venv/bin/python scripts/sweep.py scripts/examples/study.toml            # LocalCluster, 2 workers
    .venv/bin/python scripts/sweep.py STUDY --workers 1
    .venv/bin/python scripts/sweep.py STUDY --scheduler tcp://host:8786      # an existing cluster
    .venv/bin/python scripts/sweep.py STUDY --serial                         # no dask
    .venv/bin/python scripts/sweep.py STUDY --engine python                  # the Python master

The runs are made by the compiled master (tools' tld-study) unless --engine python; a study file
is checked before anything runs. scripts/examples/design.toml is a 10,125-run study.
"""
from tld_fmu.study import main

if __name__ == "__main__":
    main()
