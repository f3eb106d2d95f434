"""Layer 6, Case x Adapter -> Records: launch, runner, worker isolation, Dask lanes, timing."""
