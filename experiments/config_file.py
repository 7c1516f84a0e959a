"""config.json across versions: settings added after trials were written.

A trial's config.json holds every setting it ran with. A setting added later (the vocal tract,
`voice`) is absent from older trials, which ran with the value the setting has by default
then: `with_added_settings` fills it in when a config is read, so an old trial resumes, is
evaluated and compared as it is; `identity_form` leaves such a setting out while it has that
value, so that an old trial's checkpoints (which carry a hash of its config) stay its own.
Pure functions of dicts: every reader of config.json can use them.
"""

from __future__ import annotations

import copy

# Dotted key -> the value every trial written before the setting existed ran with.
ADDED_SETTINGS: dict[str, object] = {
    "trial.voice": "vtl",
    "world.voice": "vtl",
    "world.stick_return_reach": None,
    "world.push_objects": True,
    "world.settle_between_movements": False,
}


def with_added_settings(config: dict) -> dict:
    """A copy of a config with every added setting it lacks set to its earlier value."""
    out = copy.deepcopy(config)
    for key, value in ADDED_SETTINGS.items():
        node, last = _section(out, key)
        if node is not None and last not in node:
            node[last] = value
    return out


def identity_form(config: dict) -> dict:
    """A copy of a config without the added settings that hold their earlier value."""
    out = copy.deepcopy(config)
    for key, value in ADDED_SETTINGS.items():
        node, last = _section(out, key)
        if node is not None and node.get(last, value) == value:
            node.pop(last, None)
    return out


def _section(config: dict, key: str) -> tuple[dict | None, str]:
    """The dict that holds a dotted key's last part (None if the config lacks it), and that
    part."""
    *parents, last = key.split(".")
    node: object = config
    for parent in parents:
        node = node.get(parent) if isinstance(node, dict) else None
    return (node if isinstance(node, dict) else None), last
