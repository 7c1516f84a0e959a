"""A trial directory, in one home: where its files lie (layout.py), what its logs hold
(log_schema.py), config.json's history and identity, the records it keeps of itself (manifest,
backend, provenance, evaluations), its lock, atomic writes, the checks every reader makes and
the cleanup of a killed writer's litter. Loads no simulator.
"""
