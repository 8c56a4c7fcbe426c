"""Fetch and verify the real object meshes (YCB google_16k, BOP LINEMOD, VGN's and GIGA's clutter test
objects) into the data root (``python -m graspexp download``: :func:`download_dataset`).

Layout written (what :func:`graspexp.datasets.load_object` reads)::

    <root>/ycb/<id>/google_16k/textured.obj      from <YCB URL><id>_google_16k.tgz
    <root>/linemod/models/obj_0000NN.ply         from <LINEMOD URL>lm_models.zip (millimetres)
    <root>/vgn_clutter/<scene>/test/<file>       from <VGN_CLUTTER URL><scene>/test/<file> (vgn_pile, vgn_packed)
    <root>/.downloads/                           the archives (kept, so a re-run only verifies)
    <root>/.graspexp-hashes.json                 SHA-256 of every archive without a published hash

Base URLs: ``--base-url``, else env ``GRASPEXP_YCB_URL`` / ``GRASPEXP_LINEMOD_URL`` /
``GRASPEXP_VGN_CLUTTER_URL``, else the official hosts (for the clutter objects: the pinned commit of
``supersglzc/GIGA``, :data:`graspexp.datasets.vgn_clutter.URL`; every file is checked against the manifest
graspexp carries, :data:`graspexp.datasets.vgn_clutter.MANIFEST`). YCB publishes no checksums: the SHA-256 of an archive is recorded on its first download, once the
archive opens as a tar file (an HTML error page is refused and deleted, nothing recorded), and every
later download must match it; to reset a recorded hash, delete its entry from the registry file.
LINEMOD is checked against the published BOP SHA-256. One download runs per data root at a time (a
file lock); pooch's temporary files left by a killed download are removed by the next one, and SIGTERM
or SIGHUP during a download cleans up like Ctrl-C.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import shutil
import signal
import tarfile
import threading
import urllib.parse
import zipfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path, PurePosixPath

import pooch
from filelock import FileLock, Timeout

from graspexp.datasets import vgn_clutter
from graspexp.datasets.catalog import LINEMOD_IDS, YCB_MASS_KG
from graspexp.datasets.errors import DatasetError

YCB_URL = "https://ycb-benchmarks.s3.amazonaws.com/data/google/"
LINEMOD_URL = "https://huggingface.co/datasets/bop-benchmark/datasets/resolve/main/lm/"
URL_ENV = {
    "ycb": "GRASPEXP_YCB_URL",
    "linemod": "GRASPEXP_LINEMOD_URL",
    "vgn_clutter": "GRASPEXP_VGN_CLUTTER_URL",
}
DEFAULT_URL = {"ycb": YCB_URL, "linemod": LINEMOD_URL, "vgn_clutter": vgn_clutter.URL}
VGN_CLUTTER_SETS = {f"vgn_{scene}": scene for scene in vgn_clutter.SCENES}
"""The catalogued datasets of the clutter test objects -> their scene (the set's folder)."""
LINEMOD_ARCHIVE = "lm_models.zip"
LINEMOD_SHA256 = "cb5b5366ce620d41800c7941c2e770036c7c13c178514fa07e6a89fda5ff0e7f"
"""Published SHA-256 of BOP ``lm/lm_models.zip``."""
HASH_REGISTRY = ".graspexp-hashes.json"
ARCHIVE_DIR = ".downloads"
LOCK_NAME = ".lock"
"""In ``ARCHIVE_DIR``: held while a download runs, so leftover temporary files are known to be stale."""
POOCH_TMP_PREFIX = "tmp"
"""pooch streams each download into ``tempfile.NamedTemporaryFile(dir=...)``: ``tmp*`` in ``ARCHIVE_DIR``."""
_LINEMOD_FOLDERS = ("models", "models_eval")

log = logging.getLogger(__name__)


LOOPBACK_HOSTS = ("localhost", "127.0.0.1", "::1")
"""Hosts a plain ``http://`` base URL may name (a local mirror); any other host must be ``https://``."""


def base_url(dataset: str, override: str | None = None) -> str:
    """The base URL for ``dataset``: ``override``, else its env variable, else the official host. A YCB
    archive's hash is recorded on its first download (the set publishes none), so the first download must
    come over HTTPS (or from this machine): a plain-http URL of another host is refused."""
    url = override or os.environ.get(URL_ENV[dataset]) or DEFAULT_URL[dataset]
    parsed = urllib.parse.urlparse(url)
    if parsed.scheme not in ("https", "http", "file") or (
        parsed.scheme == "http" and parsed.hostname not in LOOPBACK_HOSTS
    ):
        raise DatasetError(
            f"base URL {url!r} is not https: archives whose hash is recorded on first download must come "
            "over https (or from localhost); give an https:// mirror"
        )
    return url if url.endswith("/") else url + "/"


def sha256_of(path: Path) -> str:
    """Hex SHA-256 of a file."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _read_registry(root: Path) -> dict[str, dict[str, str]]:
    path = root / HASH_REGISTRY
    if not path.is_file():
        return {}
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as err:
        raise DatasetError(f"hash registry {path} is not valid JSON ({err}); repair or delete it") from None
    return data if isinstance(data, dict) else {}


def _write_registry(root: Path, registry: dict[str, dict[str, str]]) -> None:
    path = root / HASH_REGISTRY
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(registry, indent=2, sort_keys=True) + "\n")
    tmp.replace(path)


def fetch(
    url: str,
    folder: Path,
    fname: str,
    sha256: str | None,
    *,
    progress: bool = True,
    reset_hint: str = "",
) -> Path:
    """Download ``url`` to ``folder/fname`` with pooch unless a copy with the right hash is there.

    ``sha256`` None accepts any content (the caller checks and records it). A hash mismatch (its message
    ends with ``reset_hint``) or an HTTP error becomes one :class:`DatasetError` naming the URL.
    """
    pooch_log = pooch.get_logger()
    level = pooch_log.level
    pooch_log.setLevel(logging.ERROR)  # we print our own hash messages
    try:
        with _download_guard(folder):
            path = pooch.retrieve(
                url,
                known_hash=f"sha256:{sha256}" if sha256 else None,
                fname=fname,
                path=folder,
                downloader=pooch.HTTPDownloader(progressbar=progress),
            )
    except ValueError as err:
        if "hash" not in str(err).lower():
            raise
        raise DatasetError(
            f"checksum mismatch for {url}: expected SHA-256 {sha256}, the downloaded file differs "
            f"(corrupted download or a changed file on the server); nothing was unpacked.{reset_hint} "
            f"Details: {err}"
        ) from None
    except OSError as err:  # requests' errors derive from OSError (IOError)
        raise DatasetError(f"download of {url} failed: {err}") from None
    finally:
        pooch_log.setLevel(level)
    return Path(path)


def _raise_signal_as_exit(signum: int, _frame: object) -> None:
    raise SystemExit(128 + signum)


@contextmanager
def _download_guard(folder: Path) -> Iterator[None]:
    """Hold the download lock of ``folder``, remove temporary files a killed download left there, and
    turn SIGTERM / SIGHUP into SystemExit so that pooch deletes its temporary file as on Ctrl-C."""
    folder.mkdir(parents=True, exist_ok=True)
    lock = FileLock(folder / LOCK_NAME, timeout=0)
    try:
        lock.acquire()
    except Timeout:
        raise DatasetError(f"another download is running into {folder}; wait for it to finish") from None
    previous = {}
    try:
        for stale in folder.glob(f"{POOCH_TMP_PREFIX}*"):
            if stale.is_file():
                stale.unlink()
        if threading.current_thread() is threading.main_thread():  # only it may install handlers
            for sig in (signal.SIGTERM, signal.SIGHUP):
                previous[sig] = signal.signal(sig, _raise_signal_as_exit)
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        lock.release()


def _check_tar(archive: Path, url: str) -> None:
    """Raise DatasetError (and delete ``archive``) unless it opens as a tar file: a first download's hash
    is recorded only for an archive that is one (not, say, an HTML error page served with status 200)."""
    try:
        with tarfile.open(archive, "r:*") as tar:
            tar.getmembers()
        return
    except (tarfile.TarError, EOFError, OSError) as err:
        head = archive.read_bytes()[:512].lstrip().lower()
        archive.unlink()
        what = (
            "an HTML page (an error page?)" if head.startswith((b"<!doctype", b"<html", b"<")) else str(err)
        )
        raise DatasetError(
            f"download of {url} is not a tar archive but {what}; it was deleted and no hash was recorded. "
            "Check the URL (--base-url / $GRASPEXP_YCB_URL) and try again"
        ) from None


def _safe_parts(name: str, archive: Path) -> tuple[str, ...]:
    parts = PurePosixPath(name.replace("\\", "/")).parts
    if not parts or name.startswith("/") or ".." in parts or ":" in parts[0]:
        raise DatasetError(f"archive {archive} holds an unsafe member path {name!r}; refusing to unpack it")
    return parts


def _untar(archive: Path, dest: Path, only: str) -> None:
    """Unpack a .tgz into ``dest``: regular files and folders only, each inside ``dest/only`` (one object's
    archive never writes over another object's verified files)."""
    try:
        with tarfile.open(archive, "r:*") as tar:
            members = []
            for member in tar.getmembers():
                parts = _safe_parts(member.name, archive)
                if parts and parts[0] != only:
                    raise DatasetError(
                        f"archive {archive} holds {member.name}, outside {only}/: an archive only unpacks its "
                        "own object; delete it and download again"
                    )
                if member.isfile() or member.isdir():
                    members.append(member)
            kwargs = {"filter": "data"} if hasattr(tarfile, "data_filter") else {}
            tar.extractall(dest, members=members, **kwargs)
    except tarfile.TarError as err:
        raise DatasetError(f"archive {archive} is not a readable tar file: {err}") from None


def download_ycb(
    root: Path | str, objects: Sequence[str], *, url: str | None = None, progress: bool = True
) -> list[Path]:
    """Fetch ``<id>_google_16k.tgz`` for each of ``objects`` into ``<root>/ycb/<id>/google_16k/``.

    The first download of an archive records its SHA-256 in ``<root>/.graspexp-hashes.json``; later
    downloads must match it. Returns the paths of the ``textured.obj`` files.
    """
    root = Path(root).expanduser()
    for name in objects:
        if name not in YCB_MASS_KG:
            raise DatasetError(
                f"unknown object {name!r} in dataset 'ycb'; valid names: {', '.join(YCB_MASS_KG)}"
            )
    archives, dest = root / ARCHIVE_DIR, root / "ycb"
    dest.mkdir(parents=True, exist_ok=True)
    registry = _read_registry(root)
    meshes = []
    for name in objects:
        fname = f"{name}_google_16k.tgz"
        source = base_url("ycb", url) + fname
        key = f"ycb/{fname}"
        known = registry.get(key, {}).get("sha256")
        hint = (
            f" If the recorded hash is the wrong one (recorded from an error page by an older version), "
            f"delete the entry {key!r} from {root / HASH_REGISTRY} and {archives / fname}, then download again."
        )
        archive = fetch(source, archives, fname, known, progress=progress, reset_hint=hint)
        if known is None:
            _check_tar(archive, source)
            digest = sha256_of(archive)
            registry[key] = {"sha256": digest, "url": source}
            _write_registry(root, registry)
            print(f"recorded SHA-256 {digest} of {fname} in {root / HASH_REGISTRY}")
        _untar(archive, dest, name)
        mesh = dest / name / "google_16k" / "textured.obj"
        if not mesh.is_file():
            raise DatasetError(f"archive {archive} did not contain {name}/google_16k/textured.obj")
        meshes.append(mesh)
    return meshes


def download_linemod(
    root: Path | str, *, url: str | None = None, sha256: str = LINEMOD_SHA256, progress: bool = True
) -> list[Path]:
    """Fetch BOP ``lm_models.zip``, verify its SHA-256, unpack ``models/`` (and ``models_eval/``).

    Files land in ``<root>/linemod/models/obj_0000NN.ply`` (millimetres). Returns the model paths.
    """
    root = Path(root).expanduser()
    source = base_url("linemod", url) + LINEMOD_ARCHIVE
    archive = fetch(source, root / ARCHIVE_DIR, LINEMOD_ARCHIVE, sha256.lower(), progress=progress)
    dest = root / "linemod"
    try:
        with zipfile.ZipFile(archive) as zf:
            for info in zf.infolist():
                parts = _safe_parts(info.filename, archive)
                hits = [i for i, part in enumerate(parts) if part in _LINEMOD_FOLDERS]
                if info.is_dir() or not hits:
                    continue
                target = dest.joinpath(*parts[hits[0] :])
                target.parent.mkdir(parents=True, exist_ok=True)
                with zf.open(info) as src, open(target, "wb") as dst:
                    shutil.copyfileobj(src, dst)
    except zipfile.BadZipFile as err:
        raise DatasetError(f"archive {archive} is not a readable zip file: {err}") from None
    models = sorted((dest / "models").glob("obj_*.ply"))
    if not models:
        raise DatasetError(f"archive {archive} held no models/obj_*.ply files")
    return models


def download_vgn_clutter(
    root: Path | str,
    scene: str,
    objects: Sequence[str],
    *,
    url: str | None = None,
    progress: bool = True,
) -> list[Path]:
    """Fetch the files of ``objects`` of the clutter test set of ``scene`` (``pile`` or ``packed``) into
    ``<root>/vgn_clutter/<scene>/test/``, each from ``<base URL><scene>/test/<file>`` and checked against its
    SHA-256 in :data:`graspexp.datasets.vgn_clutter.MANIFEST` (a file already there with the right hash is
    kept; one that differs is fetched again; a download that differs is refused). Returns the URDF paths."""
    root = Path(root).expanduser()
    names = vgn_clutter.object_names(scene)
    unknown = [n for n in objects if n not in names]
    if unknown:
        raise DatasetError(
            f"unknown object(s) {unknown} in dataset 'vgn_{scene}'; valid names: {', '.join(names)}"
        )
    hashes = vgn_clutter.scene_files(scene)
    dest = root / vgn_clutter.set_folder(scene)
    base = base_url("vgn_clutter", url) + f"{scene}/test/"
    urdfs = []
    for name in objects:
        for fname in vgn_clutter.object_files(name):
            fetch(base + fname, dest, fname, hashes[fname], progress=progress)
        urdfs.append(dest / f"{name}.urdf")
    return urdfs


def download_dataset(
    dataset: str,
    root: Path,
    objects: list[str],
    *,
    url: str | None = None,
    sha256: str | None = None,
    progress: bool = False,
) -> tuple[list[Path], list[str]]:
    """Download and verify ``objects`` of ``dataset`` (``ycb``, ``linemod``, ``vgn_pile`` or ``vgn_packed``)
    into data root ``root``: (the model files ready, the names of ``objects`` the LINEMOD archive lacks).
    ``sha256``: the expected hash of the LINEMOD archive (default the published one). Raises
    :class:`DatasetError`."""
    if dataset == "ycb":
        return download_ycb(root, objects, url=url, progress=progress), []
    if dataset in VGN_CLUTTER_SETS:
        return download_vgn_clutter(root, VGN_CLUTTER_SETS[dataset], objects, url=url, progress=progress), []
    paths = download_linemod(root, url=url, sha256=sha256 or LINEMOD_SHA256, progress=progress)
    have = {p.name for p in paths}
    return paths, [n for n in objects if f"obj_{LINEMOD_IDS[n]:06d}.ply" not in have]
