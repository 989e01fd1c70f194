"""The work-precision benchmark's parts, run in this order by bench/python/bench.py:

  native      the FMU and the plain-Rust baselines through bench/native's `tld-bench` host
  baselines   scipy solve_ivp, the pythonfmu peer and TLD.fmu through fmpy, on a window
  sweep       the design-study throughput (tld_fmu.study serially and on dask clusters)
  front       Pareto fronts and cost ratios at equal error
  findings    the targets' verdicts and the observations, computed from the run's rows
  plots       the work-precision plots, one per scene
  report      docs/BENCHMARKS.md (formats: number and label formatting shared by the above)
"""
