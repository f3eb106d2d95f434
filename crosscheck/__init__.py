"""Collision Crosscheck: run collision cases on engines and score them against an exact oracle.

The data flows one way: Case -> Observation -> Record rows -> pandas DataFrame -> CSV/HTML.
"""

__version__ = "0.1.0"
