"""Layer 7, a stored run -> CSV + HTML: render, sections, charts, compare.

A report reads only the run directory; it never imports run, adapters or cli.
"""
