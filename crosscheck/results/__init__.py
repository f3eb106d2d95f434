"""Layer 5, the seam between run and report: the results store, RunInfo, reading a run back."""
