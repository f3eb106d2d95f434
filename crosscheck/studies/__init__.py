"""Layer 7, studies built on runs: fuzzing and its findings, the harness bench, raw engine loops."""
