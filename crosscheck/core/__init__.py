"""Layer 2, the values and the contract: kinds, statuses, observations, records, options,

the case schema and the adapter contract.  Everything above imports these; they import only
:mod:`reference_impl`, pydantic and the standard library.
"""
