"""Layer 4, case files <-> Case: load, validate, expand sweeps and swaps, write TOML."""
