"""How both registries (the grasp backends', sim/grasping/registry.py; the vocal tracts',
models/tracts.py) turn a name into its class: a table of name -> "module:Class" read lazily,
as Gymnasium registers environments, so that naming or checking an entry imports nothing.

Plain Python (importlib): models/ imports nothing of the project.
"""

from __future__ import annotations

import importlib


def load_registered(registry: dict[str, str], name: str, kind: str, base: type) -> type:
    """The class registered as `name` in `registry`, its module imported now. ValueError
    naming the choices for an unknown name; TypeError if the entry is not a `base` subclass
    (`kind` names the registry's entries in both messages)."""
    target = registry.get(name)
    if target is None:
        raise ValueError(f"unknown {kind} {name!r}: choose one of {list(registry)}")
    module, _, attribute = target.partition(":")
    cls = getattr(importlib.import_module(module), attribute)
    if not (isinstance(cls, type) and issubclass(cls, base)):
        raise TypeError(f"{target} ({kind} {name!r}) is not a {base.__name__} subclass")
    return cls
