"""What every trial log records about where it came from: the job's config and seed, the data root, the
package versions, the machine, and each trial's object; Hydra's record of an accepted run."""

import functools
import hashlib
import json
import platform
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from graspexp.core.files import write_atomic
from graspexp.core.run_layout import HYDRA_FILES, hydra_dir, real_folder
from graspexp.datasets import resolve_root
from graspexp.run.objects import LoadedObject

PACKAGES = ("graspexp", "sapien", "numpy", "scikit-learn", "trimesh", "coacd", "mcap", "hydra-core")


def package_versions() -> dict[str, str]:
    """{package: version} of Python and of :data:`PACKAGES` ("unknown" for one not installed)."""
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "unknown"
    return out


@functools.cache
def machine_fingerprint() -> dict[str, str]:
    """What a trial's floating point may depend on besides the code: CPU model, its instruction-set flags
    (a hash: PhysX and numba pick vector paths by them), OS and architecture."""
    cpu, flags = platform.processor() or "unknown", ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name" and cpu in ("unknown", "", platform.machine()):
                cpu = value.strip()
            elif key.strip() in ("flags", "Features") and not flags:
                flags = " ".join(sorted(value.split()))
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cpu_flags_sha256": hashlib.sha256(flags.encode()).hexdigest()[:16],
        "platform": platform.platform(),
        "arch": platform.machine(),
    }


X86_V4 = frozenset({"avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl"})
"""The CPU flags of the x86-64-v4 level (AVX-512)."""
X86_V3 = frozenset({"avx", "avx2", "bmi1", "bmi2", "f16c", "fma", "movbe"})
"""The CPU flags of the x86-64-v3 level (AVX2, FMA)."""


@functools.cache
def cpu_flags() -> frozenset[str] | None:
    """The CPU's instruction-set flags (the first ``flags`` line of /proc/cpuinfo; empty where it has none),
    or None when /proc/cpuinfo cannot be read."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return None
    return next(
        (frozenset(ln.split(":", 1)[1].split()) for ln in lines if ln.startswith("flags")), frozenset()
    )


@functools.cache
def cpu_class() -> str:
    """The CPU class a results fingerprint holds on (``x86_64-v4-intel``, ``x86_64-v3-amd``, ..., or the
    architecture's name elsewhere): the x86-64 level and the vendor. numpy's vector loops, OpenBLAS's kernels
    and numba's code are chosen by the instruction set and the core type at run time, and the last bits they
    leave can turn a simulated trial. Measured: the readings' default sweep (Tables 1 and 2, 10 drops per
    object and setting) turns 0 to 3 of the 90 YCB trials per setting on an AVX-512 machine against AVX2
    ones, and no LINEMOD trial; an Intel Xeon with AVX-512 gives other fingerprints than an AMD EPYC with
    AVX-512 for every page (OpenBLAS's SkylakeX kernels against Zen's, among others)."""
    arch = platform.machine()
    if arch != "x86_64":
        return arch or "unknown"
    flags = cpu_flags()
    if flags is None:
        return "x86_64"
    level = 4 if X86_V4 <= flags and X86_V3 <= flags else 3 if X86_V3 <= flags else 2
    vendor = VENDORS.get(cpu_vendor(), cpu_vendor().lower())
    return f"x86_64-v{level}" + (f"-{vendor}" if vendor else "")


VENDORS = {"GenuineIntel": "intel", "AuthenticAMD": "amd"}
"""Short names of the ``vendor_id`` of /proc/cpuinfo in a CPU class."""


@functools.cache
def cpu_vendor() -> str:
    """The CPU's ``vendor_id`` (/proc/cpuinfo; ``""`` where it has none or cannot be read)."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return ""
    return next((ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("vendor_id")), "")


def job_metadata(cfg: DictConfig) -> dict[str, str]:
    """The part of every trial's MCAP metadata that is the same for the whole job: the config, the seed,
    the data root it read, the package versions and the machine (:func:`machine_fingerprint`)."""
    meta = {"config_yaml": OmegaConf.to_yaml(cfg, resolve=True), "global_seed": str(cfg.seed)}
    meta["data_root"] = str(resolve_root(cfg.dataset).resolve())
    meta.update({f"version.{k}": v for k, v in package_versions().items()})
    meta.update({f"machine.{k}": v for k, v in machine_fingerprint().items()})
    return meta


def trial_metadata(job_meta: dict[str, str], loaded: LoadedObject, trial: int, seed: int) -> dict[str, str]:
    """One trial's log metadata: the job's, the trial's seeds and what its object was made of (the mesh
    file, "" for a procedural one, the SHA-256 of the geometry used with its face count, surface area and
    volume, the collision method it got with its cache key and the SHA-256 of the shape itself, the
    SHA-256 of its grasping area, and what was assumed for it: units, mass, area)."""
    return {
        **job_meta,
        "object": loaded.model.name,
        "trial": str(trial),
        "trial_seed": str(seed),
        **object_metadata(loaded),
    }


def object_metadata(loaded: LoadedObject) -> dict[str, str]:
    """What an object of a trial was made of (:func:`trial_metadata`), also what the run record keeps of each
    object (:mod:`graspexp.run.run_record`)."""
    return {
        "mesh_source": loaded.model.source,
        "mesh_sha256": loaded.model.mesh_sha256,
        **loaded.model.mesh_facts,
        "collision_method": loaded.hulls.method,
        "collision_key": loaded.hulls.key,
        "collision_sha256": loaded.hulls.sha256,
        "area_sha256": loaded.model.area_sha256,
        "object_notes": "\n".join(loaded.notes),
    }


POOL_KEYS = ("mesh_source", "mesh_sha256", "collision_sha256", "area_sha256")
"""What a clutter round's log records of each object of its pool (:func:`pool_metadata`)."""


def pool_metadata(pool: list[LoadedObject]) -> str:
    """A clutter job's pool as its round logs record it (metadata ``round_pool``): a JSON list, in the pool's
    order (a round draws its objects by position), of each object's name and :data:`POOL_KEYS`; what resume
    compares before reusing a round and ``replay --resim`` before re-simulating one."""
    entries = [{"name": o.model.name, **{k: object_metadata(o)[k] for k in POOL_KEYS}} for o in pool]
    return json.dumps(entries, separators=(",", ":"))


def recorded_pool(meta: dict) -> list[dict[str, str]] | None:
    """The pool a round log's metadata (or the run record) records (:func:`pool_metadata`); None when it
    records none (a round logged before graspexp recorded pools); ValueError for one that is not such a
    list."""
    text = meta.get("round_pool")
    if text is None:
        return None
    entries = json.loads(text) if isinstance(text, str) else text
    if not isinstance(entries, list) or not all(
        isinstance(e, dict) and isinstance(e.get("name"), str) and all(isinstance(v, str) for v in e.values())
        for e in entries
    ):
        raise ValueError("its recorded round_pool is not a list of objects with their mesh hashes")
    return entries


def unusable_trial_metadata(
    job_meta: dict[str, str], object_name: str, trial: int, seed: int
) -> dict[str, str]:
    """The log metadata of a trial whose object could not be loaded (no mesh facts to record)."""
    return {**job_meta, "object": object_name, "trial": str(trial), "trial_seed": str(seed)}


def write_hydra_record(cfg: DictConfig, run_dir: Path) -> None:
    """Hydra's record of an accepted run, ``.hydra/{config,hydra,overrides}.yaml`` (written here, after the
    checks, rather than by Hydra before them: ``hydra.output_subdir`` is null in ``conf/config.yaml``)."""
    from hydra.core.hydra_config import HydraConfig

    hc = HydraConfig.get()
    folder = real_folder(run_dir, hydra_dir(run_dir))
    texts = (
        OmegaConf.to_yaml(cfg),
        OmegaConf.to_yaml({"hydra": hc}),
        OmegaConf.to_yaml(list(hc.overrides.task)),
    )
    for name, text in zip(HYDRA_FILES, texts, strict=True):  # replaced whole, never through a link
        data = text.encode()
        write_atomic(folder / name, lambda fh, data=data: fh.write(data))
