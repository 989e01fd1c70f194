"""Design studies with TLD.fmu on dask.distributed (python/tld_fmu/study.py):

    .venv/bin/python scripts/sweep.py scripts/examples/study.toml            # LocalCluster, 2 workers
    .venv/bin/python scripts/sweep.py STUDY --workers 1
    .venv/bin/python scripts/sweep.py STUDY --scheduler tcp://host:8786      # an existing cluster
    .venv/bin/python scripts/sweep.py STUDY --serial                         # no dask
"""
from tld_fmu.study import main

if __name__ == "__main__":
    main()
