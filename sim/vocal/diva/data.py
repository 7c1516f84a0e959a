"""DIVA's fitted map from the user's file: checked, identified, cached; never shipped.

DIVA's data (`diva_synth.mat`) comes with no licence that lets this project redistribute it
(none in the Guenther lab's DIVAsimulink repository, nor in the divapy copy; docs/protocol.md
D13), so the user provides it once:

    playroom voice-data diva PATH

`install` reads the file (MATLAB v5: DIVA's `diva_synth.mat` with its `fmfit` struct, or
divapy's flattened `fmfit_py.mat`), checks its structure, identifies it by its SHA-256 and by
the digest of its map, and writes the map into the user's data directory ($PLAYROOM_DATA_DIR,
else platformdirs' user data directory: ~/.local/share/playroom on Linux). `installed_fit`
reads it back for every DIVA voice; without it, `DivaDataMissing` says in one line what to run
and where the file is found. Only the study's map is accepted: the later DIVA releases refit
the map (128 components), which would be another vocal tract than the study's.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from sim.vocal.diva.fmfit import FormantFit

DATA_ENV = "PLAYROOM_DATA_DIR"
CACHE_NAME = "diva-fmfit.npz"
WHERE_TO_GET = (
    "diva_synth.mat from the DIVA model's distribution (github.com/GuentherLab/DIVAsimulink at "
    "commit 6493b49, or DivaMatlab/diva_synth.mat in github.com/yumilceh/divapy)"
)
# Files known by their SHA-256: (what it is, whether its map is the study's).
KNOWN_FILES: dict[str, tuple[str, bool]] = {
    "cbdb6eab4ba727fa6aa9b4cff3aeb364eab662800c92e6f8b07bfe7104485980": (
        "diva_synth.mat of early 2017 (yumilceh/divapy DivaMatlab/), the study's DIVA",
        True,
    ),
    "20a21448060b0902e81398449d6919d0892070b3d810311da1667b44a042f36d": (
        "diva_synth.mat of GuentherLab/DIVAsimulink 6493b49 (2020-07-09), the study's map",
        True,
    ),
    "9aab89133d0c1c0324984a429c879169241de90b153a774d48f1d2c737de9486": (
        "fmfit_py.mat of yumilceh/divapy (data/), the study's map converted",
        True,
    ),
    "2284337394372ed9359f0dd6a2a8a1ba4a3c2f2035874c38a2014ae6ec271dc0": (
        "diva_synth.mat of GuentherLab/DIVAsimulink 8a24a9b (2020-08-25), 128 components",
        False,
    ),
    "b3831b3f49c177cdab61fa416c4b1efe75fc819fc75a3b57b03e454d97b973c0": (
        "diva_synth.mat of GuentherLab/DIVAsimulink e58c63d (2021-04-01), 128 components",
        False,
    ),
}
# The digest of the study's map (`map_digest`): whatever file holds it, this is the map run.
STUDY_MAP_DIGEST = "3513f3c52b483577"
FIELDS = ("mu", "iSigma", "p", "beta_fmt")
_FLAT_KEYS = {
    "mu": "fmfit_mu",
    "iSigma": "fmfit_isigma",
    "p": "fmfit_p",
    "beta_fmt": "fmfit_beta_fmt",
}


class DivaDataError(ValueError):
    """A file that is not DIVA's map, or not the study's; the message says which and why."""


class DivaDataMissing(FileNotFoundError):
    """No DIVA map installed: the message names the file and the command that installs it."""


def data_dir() -> Path:
    """Where installed voice data lives: $PLAYROOM_DATA_DIR, else the user's data directory."""
    if os.environ.get(DATA_ENV):
        return Path(os.environ[DATA_ENV])
    import platformdirs

    return Path(platformdirs.user_data_dir("playroom"))


def cache_path() -> Path:
    return data_dir() / CACHE_NAME


def map_digest(fit: FormantFit) -> str:
    """16 hex digits of SHA-256 over the map's numbers (float64, C order): the map's identity,
    the same whichever file or layout it came from."""
    h = hashlib.sha256()
    for array in (fit.mu, fit.i_sigma, fit.p, fit.beta_fmt):
        h.update(np.ascontiguousarray(array, dtype=np.float64).tobytes())
    return h.hexdigest()[:16]


def read_fit(path: str | os.PathLike) -> FormantFit:
    """The map in a DIVA file (either layout); DivaDataError naming what is wrong."""
    import scipy.io

    path = Path(path)
    if not path.is_file():
        raise DivaDataError(f"{path} is not a file: expected {WHERE_TO_GET}")
    try:
        content = scipy.io.loadmat(str(path), squeeze_me=False)
    except Exception as exc:  # scipy raises several kinds for a file that is not MATLAB's
        raise DivaDataError(f"{path} is not a MATLAB .mat file ({exc})") from None
    if "fmfit" in content:
        struct = content["fmfit"]
        names = struct.dtype.names or ()
        missing = [f for f in FIELDS if f not in names]
        if missing:
            raise DivaDataError(f"{path}: its fmfit struct lacks {', '.join(missing)}")
        arrays = {f: np.asarray(struct[f][0, 0], dtype=float) for f in FIELDS}
    elif all(k in content for k in _FLAT_KEYS.values()):
        arrays = {f: np.asarray(content[k], dtype=float) for f, k in _FLAT_KEYS.items()}
    else:
        raise DivaDataError(
            f"{path} holds no DIVA map (neither an fmfit struct nor fmfit_* arrays): expected "
            f"{WHERE_TO_GET}"
        )
    try:
        return FormantFit(
            mu=arrays["mu"],
            i_sigma=arrays["iSigma"],
            p=arrays["p"].reshape(-1),
            beta_fmt=arrays["beta_fmt"],
        )
    except (ValueError, TypeError) as exc:
        raise DivaDataError(f"{path}: {exc}") from None


def file_sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def identify(path: str | os.PathLike) -> tuple[FormantFit, str]:
    """The map in the user's file and what the file is; DivaDataError for a file that is not
    DIVA's map or holds another map than the study's."""
    path = Path(path)
    fit = read_fit(path)
    known = KNOWN_FILES.get(file_sha256(path))
    if map_digest(fit) != STUDY_MAP_DIGEST:
        what = known[0] if known else f"an unknown DIVA map with {fit.n_components} components"
        raise DivaDataError(
            f"{path} is {what}, not the map the study ran (32 components, early 2017): get "
            f"{WHERE_TO_GET}"
        )
    return fit, known[0] if known else "an unlisted file holding the study's map"


def install(path: str | os.PathLike) -> tuple[Path, str]:
    """Check the user's DIVA file and cache its map: (cache path, what the file is).

    DivaDataError, with nothing written, for a file that is not DIVA's map or not the study's.
    The cache is written whole or not at all (a temporary file renamed into place).
    """
    fit, what = identify(path)
    target = cache_path()
    target.parent.mkdir(parents=True, exist_ok=True)
    meta = {
        "map_digest": map_digest(fit),
        "source": str(Path(path).resolve()),
        "source_sha256": file_sha256(Path(path)),
        "source_is": what,
    }
    handle, temporary = tempfile.mkstemp(dir=target.parent, prefix=".diva-", suffix=".npz")
    try:
        with os.fdopen(handle, "wb") as out:
            np.savez(
                out,
                mu=fit.mu,
                i_sigma=fit.i_sigma,
                p=fit.p,
                beta_fmt=fit.beta_fmt,
                meta=np.array(json.dumps(meta)),
            )
        os.replace(temporary, target)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    _read_cache.cache_clear()
    return target, what


def installed_fit() -> FormantFit:
    """The installed map (read once per process and place); DivaDataMissing when none is
    installed, DivaDataError when the cache is damaged."""
    return _read_cache(cache_path())


@functools.cache
def _read_cache(path: Path) -> FormantFit:
    if not path.is_file():
        raise DivaDataMissing(
            f"the voice diva needs DIVA's map, which is not installed ({path} is missing): get "
            f"{WHERE_TO_GET}, then run `playroom voice-data diva PATH`"
        )
    damaged = DivaDataError(
        f"{path} is damaged or not the study's map: run `playroom voice-data diva PATH` again"
    )
    try:
        with np.load(path) as stored:
            meta = json.loads(str(stored["meta"]))
            fit = FormantFit(
                mu=stored["mu"],
                i_sigma=stored["i_sigma"],
                p=stored["p"],
                beta_fmt=stored["beta_fmt"],
            )
    except (OSError, ValueError, KeyError, zipfile.BadZipFile):  # what a damaged npz raises
        raise damaged from None
    if map_digest(fit) != meta.get("map_digest") or meta.get("map_digest") != STUDY_MAP_DIGEST:
        raise damaged
    return fit
