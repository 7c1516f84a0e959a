"""Grasp backends: how the arm moves and what it takes, one module per backend.

- `names`: the backends' names and the default one (no MuJoCo: the command line reads them).
- `base`: `GraspBackend`, what every backend offers the room, the task, the caregiver and the
  experimenter; `ClosedForm`, what a backend whose movements are closed-form geometry adds.
- `kinematic`: the study's distance rules, stepped and in closed form side by side.
- `physical`: grasping through MuJoCo contacts and welds.
- `registry`: name -> backend class (`BACKENDS`, `backend_class`).

Adding a backend: a module with a `GraspBackend` subclass, its name in `names.GRASPS`, its
class in `registry.BACKENDS`.
"""
