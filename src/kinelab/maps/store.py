"""A reachability map in memory or on disk (a Zarr directory, written chunk by chunk).

On disk: arrays ``centres`` (V, 3) [m], ``reachability``, ``manipulability``, ``sigma_ratio`` (V,) and
``done`` (one flag per chunk, set after the chunk's values are written, so an interrupted run resumes at
the first chunk not done), with the metadata in the group's attributes: robot name, SHA-256 of its model
file, the spec, the voxel count and the kinelab version. Zarr is the optional extra ``kinelab[maps]``.
"""

from __future__ import annotations

import hashlib
import shutil
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

import kinelab
from kinelab.errors import KinelabError, OptionError
from kinelab.files import as_path, output_folder
from kinelab.robot import Chain

if TYPE_CHECKING:
    from kinelab.maps.chunk import MapSpec

INSTALL_HINT = "pip install 'kinelab[maps]' (zarr)"
VALUES = ("reachability", "manipulability", "sigma_ratio", "branches")


def _zarr() -> Any:
    try:
        import zarr
    except ImportError:
        raise KinelabError(f"writing or reading a map file needs zarr: {INSTALL_HINT}") from None
    return zarr


def model_sha256(robot: Chain) -> str:
    """SHA-256 of the robot's model file (the map's, and every worker's, proof of the same robot)."""
    if robot.urdf_path is None:  # an in-memory model: its own serialisation
        return hashlib.sha256(robot.model.saveToString().encode()).hexdigest()
    return hashlib.sha256(Path(robot.urdf_path).read_bytes()).hexdigest()


def metadata(robot: Chain, spec: MapSpec, voxels: int) -> dict:
    """What identifies a map: the robot, its model file's hash, the spec and the kinelab version."""
    return {"robot": robot.name, "source_sha256": model_sha256(robot),
            "spec": spec.to_dict(), "solver": "analytic" if spec.closed_form(robot) else "frdm",
            "voxels": int(voxels), "kinelab": kinelab.__version__,
            "base": robot.base, "tool": robot.tool}


def centres_sha256(centres: np.ndarray) -> str:
    """SHA-256 of the voxel centres (little-endian float64, row by row): kept with the map, checked on open."""
    return hashlib.sha256(np.ascontiguousarray(centres, dtype="<f8").tobytes()).hexdigest()


def _read(array: Any, where: slice | int, what: str, path: Path | None) -> np.ndarray:
    """``array[where]`` as numpy; a chunk file that does not decode is a KinelabError naming the array."""
    try:
        return np.asarray(array[where])
    except Exception as exc:  # noqa: BLE001 - zarr and its codecs raise RuntimeError, ValueError, ... on garbage
        raise KinelabError(f"{path}: the {what} array cannot be read ({type(exc).__name__}: {exc}); the map file "
                           "is damaged: remove it and compute the map again") from None


def _text(value: Any) -> bool:
    return isinstance(value, str) and value != ""


def _count(value: Any, least: int = 0) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= least


def _positive(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and 0.0 < value < float("inf")


# what a map's metadata holds and how each item must look (a store is data: an edited one is refused by name)
_META = {
    "robot": _text, "source_sha256": _text, "kinelab": _text, "solver": _text, "centres_sha256": _text,
    "voxels": _count, "base": lambda v: v is None or _text(v), "tool": lambda v: v is None or _text(v),
}
_SPEC = {"voxel": _positive, "orientations": lambda v: _count(v, 1), "chunk_voxels": lambda v: _count(v, 1)}


def _check_meta(meta: dict, path: Path) -> None:
    """Refuse metadata with an item missing or of the wrong kind, naming it."""
    spec = meta.get("spec")
    if not isinstance(spec, dict):
        raise KinelabError(f"{path}: the map's metadata is damaged: 'spec' is {spec!r}, not a table; compute the map "
                           "again")
    for table, rules, where in ((meta, _META, ""), (spec, _SPEC, "spec.")):
        for key, ok in rules.items():
            if not ok(table.get(key)):
                raise KinelabError(f"{path}: the map's metadata is damaged: {where}{key} is {table.get(key)!r}; "
                                   "compute the map again")


def _check_layout(meta: dict, arrays: dict[str, Any], path: Path) -> None:
    """Refuse a map whose metadata is damaged, whose arrays do not have the shapes and types its metadata implies,
    whose centres were not all written (a store declaring more voxels than it holds) or differ from the ones it was
    written with (an edited or truncated store)."""
    _check_meta(meta, path)
    voxels, size = meta["voxels"], meta["spec"]["chunk_voxels"]
    chunks = -(-voxels // size)
    expected = {"centres": ((voxels, 3), "f8"), "done": ((chunks,), "bool"), "checksums": ((chunks, 32), "u1"),
                **{k: ((voxels,), "f8") for k in VALUES}}
    for name, (shape, dtype) in expected.items():
        found = arrays[name]
        if tuple(found.shape) != shape or np.dtype(found.dtype) != np.dtype(dtype):
            raise KinelabError(f"{path}: array {name!r} has shape {tuple(found.shape)} and type {found.dtype}; a map "
                               f"of {voxels} voxels in chunks of {size} has {shape} {np.dtype(dtype)}: the file was "
                               "altered, compute the map again")
    centres = arrays["centres"]
    if centres.nchunks_initialized != centres.nchunks:  # a map writes its centres whole, before any value
        raise KinelabError(f"{path}: the voxel centres were not all written ({centres.nchunks_initialized} of "
                           f"{centres.nchunks} chunks): the file was altered, compute the map again")
    if centres_sha256(_read(centres, slice(None), "centres", path)) != meta.get("centres_sha256"):
        raise KinelabError(f"{path}: the voxel centres no longer match the checksum written with them: the file was "
                           "altered, compute the map again")


class ReachabilityMap:
    """The map's arrays (numpy, or Zarr arrays on disk) and its metadata."""

    def __init__(self, meta: dict, arrays: dict[str, Any], path: Path | None = None):
        self.meta, self.path = meta, path
        self.centres, self.done = arrays["centres"], arrays["done"]
        self.values = {k: arrays[k] for k in VALUES}
        self.checksums = arrays.get("checksums")  # (chunks, 32) SHA-256 of each written chunk (on disk only)

    @property
    def chunks(self) -> int:
        """How many chunks the map has."""
        return len(self.done)

    def write(self, index: int, values: dict[str, np.ndarray]) -> None:
        """Store chunk ``index``'s values, then mark it done.

        Raises:
            KinelabError: the disk refused (full, say): the chunks done before it are kept, and the same call
                resumes the map once there is room.
        """
        size = self.meta["spec"]["chunk_voxels"]
        try:
            for name in VALUES:
                self.values[name][index * size:index * size + len(values[name])] = values[name]
            if self.checksums is not None:
                self.checksums[index] = self._digest(index)
            self.done[index] = True
        except OSError as err:
            raise KinelabError(f"cannot write chunk {index} of the map to {self.path}: {err.strerror or err}; the "
                               f"{self.finished()[0]} chunk(s) done are kept: run the same map again to resume"
                               ) from None

    def finished(self) -> tuple[int, int]:
        """(chunks done, chunks in all): a map whose run was interrupted has fewer done."""
        return int(np.count_nonzero(_read(self.done, slice(None), "done", self.path))), self.chunks

    def _digest(self, index: int) -> np.ndarray:
        """SHA-256 of chunk ``index``'s stored values, as 32 bytes."""
        size = self.meta["spec"]["chunk_voxels"]
        h = hashlib.sha256()
        for name in VALUES:
            try:
                values = np.asarray(self.values[name][index * size:(index + 1) * size])
            except Exception:  # noqa: BLE001 - a chunk file that does not decode: damaged, like one altered
                return np.zeros(32, dtype=np.uint8)  # no SHA-256 is all zeros
            h.update(np.ascontiguousarray(values, dtype="<f8").tobytes())
        return np.frombuffer(h.digest(), dtype=np.uint8)

    def damaged(self) -> list[int]:
        """The chunks marked done whose stored values no longer match the checksum written with them (a chunk
        file deleted or altered); none for a map in memory."""
        if self.checksums is None:
            return []
        done = np.flatnonzero(_read(self.done, slice(None), "done", self.path))
        sums = _read(self.checksums, slice(None), "checksums", self.path)
        return [int(c) for c in done if not np.array_equal(sums[c], self._digest(int(c)))]

    def array(self, name: str) -> np.ndarray:
        """One of ``reachability``, ``manipulability``, ``sigma_ratio``, ``branches`` (or ``centres``) as a numpy
        array."""
        return np.asarray(self.centres[:] if name == "centres" else self.values[name][:])


def open_map(out: str | Path | None, robot: Chain, spec: MapSpec, centres: np.ndarray) -> ReachabilityMap:
    """A new map (in memory, or a new Zarr directory), or the unfinished one at ``out`` if it is the same map.

    Raises:
        KinelabError: ``out`` holds another map (the differing item named), or zarr is missing.
    """
    meta = metadata(robot, spec, len(centres))
    chunks = -(-len(centres) // spec.chunk_voxels)
    if out is None:
        arrays = {"centres": centres, "done": np.zeros(chunks, dtype=bool),
                  **{k: np.full(len(centres), np.nan) for k in VALUES}}
        return ReachabilityMap(meta, arrays)
    zarr, path = _zarr(), output_folder(out, "map")
    if path.exists():
        found = load(path, check=False)
        _same(found.meta, meta, path)
        damaged = found.damaged()
        for c in damaged:
            found.done[c] = False
        if damaged:
            warnings.warn(f"{path}: {len(damaged)} chunk(s) no longer match their checksums (first: {damaged[0]}); "
                          "they are computed again", stacklevel=3)
        return found
    try:
        group = zarr.open_group(str(path), mode="w")
        group.attrs.update({**meta, "centres_sha256": centres_sha256(centres)})
        group.create_dataset("centres", data=centres, chunks=(spec.chunk_voxels, 3))
        for name in VALUES:
            group.create_dataset(name, shape=(len(centres),), chunks=(spec.chunk_voxels,), dtype="f8",
                                 fill_value=np.nan)
        group.create_dataset("checksums", shape=(chunks, 32), chunks=(1, 32), dtype="u1", fill_value=0)
        group.create_dataset("done", shape=(chunks,), chunks=(1,), dtype=bool, fill_value=False)
    except (KeyError, OSError) as err:  # zarr's directory store says KeyError for a file it cannot create
        shutil.rmtree(path, ignore_errors=True)  # it was new: half a store would block the next run
        why = getattr(err, "strerror", None) or "not a writable folder"
        raise KinelabError(f"cannot write the map to {path}: {why}; nothing was left there") from None
    return ReachabilityMap(meta, {k: group[k] for k in ("centres", "done", "checksums", *VALUES)}, path)


def load(path: str | Path, check: bool = True) -> ReachabilityMap:
    """Open a map written by :func:`kinelab.maps.reachability`.

    Args:
        path: the Zarr directory.
        check: verify every finished chunk against its checksum.

    Raises:
        KinelabError: no map there, a map written by another kinelab version (named), or (with ``check``)
            chunks whose values no longer match their checksums (running the same map again recomputes them).
    """
    if not isinstance(check, bool):
        raise OptionError("check", check, "True or False (verify every finished chunk's checksum)")
    zarr, path = _zarr(), as_path(path, "a reachability map", KinelabError)
    try:
        group = zarr.open_group(str(path), mode="r+")
        meta = dict(group.attrs)
        arrays = {k: group[k] for k in ("centres", "done", "checksums", *VALUES)}
    except (KeyError, ValueError, TypeError, OSError, zarr.errors.GroupNotFoundError):
        raise KinelabError(f"{path} is not a kinelab reachability map (or its metadata is damaged)") from None
    if meta.get("kinelab") != kinelab.__version__:
        raise KinelabError(f"{path} was written by kinelab {meta.get('kinelab')}, this is {kinelab.__version__}: "
                           "compute the map again")
    _check_layout(meta, arrays, path)
    found = ReachabilityMap(meta, arrays, path)
    damaged = found.damaged() if check else []
    if damaged:
        raise KinelabError(f"{path}: {len(damaged)} chunk(s) no longer match their checksums (first: {damaged[0]}); "
                           "run the same map again to compute them anew")
    return found


def _same(found: dict, wanted: dict, path: Path) -> None:
    for key in ("robot", "source_sha256", "base", "tool", "spec", "voxels"):
        if found.get(key) != wanted.get(key):
            raise KinelabError(f"{path} holds another map ({key}: {found.get(key)!r}, asked for "
                               f"{wanted.get(key)!r}); give another --out or remove it")
