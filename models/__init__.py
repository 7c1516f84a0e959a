"""The playroom's MJCF model, shipped inside the package so an installed wheel finds it."""

from importlib import resources
from pathlib import Path

PLAYROOM_XML = "playroom.xml"


def playroom_xml() -> Path:
    """Path of models/playroom.xml wherever the package is installed."""
    # Installed packages are plain directories (the project's wheel is not zip-safe), so the
    # resource is a real file that MuJoCo's parser can open.
    return Path(str(resources.files(__name__) / PLAYROOM_XML))
