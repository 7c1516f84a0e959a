"""Grasp backends: how the arm moves and what it takes, one module per backend.

- `registry`: `REGISTRY`, name -> "module:Class", the one table of the backends (lazy: it
  imports none), and `load(name)`, which imports one.
- `names`: the backends' names (the registry's keys) and the default one; no MuJoCo, so the
  command line reads them.
- `base`: `GraspBackend`, what every backend offers the room (one `simulate` per movement),
  the caregiver and the experimenter, and what it declares for the trial's record (`reach`,
  `capabilities`).
- `kinematic`: the study's distance rules over a whole movement, in closed form.
- `physical`: grasping through MuJoCo contacts and welds, its steps compiled.

Adding a backend: a module with a `GraspBackend` subclass and one line in
`registry.REGISTRY`; tests/sim/test_backend_contract.py runs every registered backend.
"""
