"""Python code shared by the project's scripts, tests and benchmarks (installed in editable
mode into the project's venv by scripts/pyenv).

Modules (imported on demand; none is loaded by importing the package):
  paths      where things are in the repository, and the tools cargo builds
  contract   the FMU's contract read from modelDescription.xml: value references by variable
             name, enumeration values by item name
  reference  independent reference solutions of the model's equations (no FMU involved)
  slave      one FMU instance driven through fmpy, with its log captured and fast fixed-step runs
  sdof       the Table 2.1 structure and its co-simulation master (scripts/demo.py, fig25.py)
  building   an N-storey shear building master with TLD.fmu instances (scripts/building.py)
  study      design studies on dask.distributed (scripts/sweep.py); studyfile (the study TOML,
             checked), studyplots (heat maps, design chart)
  native     the client of tools' tld-study, the design studies' compiled master
  peaks      a response peak located to a stated tolerance by golden-section search from a sweep's
             grid (scripts/demo.py, building.py, fig25.py, study)
  scenes     the work-precision benchmark's scenes, references and job lines (bench/python/bench.py,
             scripts/models.py)
"""
