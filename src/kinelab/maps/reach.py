"""A reachability map, chunk by chunk, in this process or on a Dask cluster (:mod:`kinelab.maps.cluster`).

The chunks and the spec are :mod:`kinelab.maps.chunk`'s; the storage :mod:`kinelab.maps.store`'s.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinelab.errors import KinelabError, OptionError
from kinelab.maps import cluster, grid, store
from kinelab.maps.chunk import MAX_TARGETS, MapSpec, compute_chunk
from kinelab.progress import bar
from kinelab.robot import Chain

if TYPE_CHECKING:
    import numpy as np
    from distributed import Client

__all__ = ["MAX_TARGETS", "MapSpec", "compute_chunk", "reachability"]


def spec_of(spec: MapSpec | None, fields: dict[str, Any]) -> MapSpec:
    """The map's :class:`MapSpec`: ``spec`` as given, or one built from its fields, checked.

    Raises:
        OptionError: ``spec`` is not a MapSpec, both are given, or a field it does not have (the fields listed).
    """
    if spec is not None and not isinstance(spec, MapSpec):
        raise OptionError("spec", spec, "a kinelab.maps.MapSpec, or its fields as keyword arguments")
    if spec is not None and fields:
        raise OptionError(next(iter(fields)), "given with spec=", "either spec=MapSpec(...) or its fields")
    names = [f.name for f in dataclasses.fields(MapSpec)]
    unknown = [k for k in fields if k not in names]
    if unknown:
        raise OptionError(unknown[0], fields[unknown[0]], ", ".join(names),
                          f"unknown map field {unknown[0]!r}; a map's fields are: {', '.join(names)}")
    made = spec or MapSpec(**fields)
    made.check()
    return made


def reachability(robot: Chain, spec: MapSpec | None = None, out: str | None = None, force: bool = False,
                 progress: bool | None = None, client: Client | None = None, **fields: Any) -> Any:
    """The reachability map of ``robot``, computed in this process chunk by chunk (written to ``out`` as they
    finish when given: an interrupted run resumes from the chunks already there).

    Args:
        robot: the robot; the map's voxels are in its base frame.
        spec: the map's parameters (:class:`MapSpec`), or its fields as keyword arguments.
        out: a Zarr directory to write (None: in memory only).
        force: run a map of more than MAX_TARGETS targets.
        progress: show a bar over the chunks (None: in a terminal or Jupyter, not in a pipe or a log); a resumed
            map's bar starts at the chunks already written.
        client: a ``dask.distributed.Client``: the chunks run on its cluster (:mod:`kinelab.maps.cluster`);
            None: in this process, on all cores.
        fields: the spec's fields as keyword arguments, instead of ``spec``.

    Returns:
        The :class:`~kinelab.maps.store.ReachabilityMap`.

    Raises:
        KinelabError: a bad spec, a map too large without ``force``, or ``out`` holding another map.
    """
    spec = spec_of(spec, fields)
    _check_out_and_client(out, client)
    centres = _checked_centres(robot, spec, force)
    target = store.open_map(out, robot, spec, centres)
    todo = [c for c in range(target.chunks) if not target.done[c]]
    if client is not None:
        cluster.run_chunks(client, robot, spec, centres, todo, target, progress)
        return target
    _run_here(robot, spec, centres, todo, target, out, progress)
    return target


def _check_out_and_client(out: object, client: object) -> None:
    """``out`` is a folder path or None, ``client`` a Dask client or None.

    Raises:
        OptionError: either one otherwise.
    """
    if out is not None and not (isinstance(out, Path) or (isinstance(out, str) and out.strip())):
        raise OptionError("out", out, "a folder path (a str or pathlib.Path), or None (in memory)")
    if client is not None and not (callable(getattr(client, "submit", None)) and hasattr(client, "scatter")):
        raise OptionError("client", client, "a dask.distributed.Client, or None (this process)")


def _checked_centres(robot: Chain, spec: MapSpec, force: bool) -> np.ndarray:
    """The map's voxel centres, refused where the map asks for more than MAX_TARGETS targets without ``force``: on
    the estimate before the grid is built (a 1e-9 m voxel, say), then on the count.

    Raises:
        KinelabError: a map too large without ``force``.
    """
    estimate = grid.estimated_voxels(robot, spec.voxel) * spec.orientations
    if estimate > 1.2 * MAX_TARGETS and not force:
        raise KinelabError(f"this map asks for about {estimate:.3g} targets (counted before any grid is built); the "
                           f"limit is {MAX_TARGETS} without "
                           "force=True (--force): a larger voxel or fewer orientations make it smaller")
    centres = grid.voxel_centres(robot, spec.voxel)
    total = len(centres) * spec.orientations
    if total > MAX_TARGETS and not force:
        raise KinelabError(f"this map asks for {total} targets ({len(centres)} voxels × {spec.orientations}); the "
                           f"limit is {MAX_TARGETS} without force=True (--force): a larger voxel or fewer "
                           "orientations make it smaller")
    return centres


def _run_here(robot: Chain, spec: MapSpec, centres: np.ndarray, todo: list[int], target: store.ReachabilityMap,
              out: object, progress: bool | None) -> None:
    """The chunks left, in this process, each written as it finishes, under a bar that starts at those done."""
    resumed = target.chunks - len(todo)
    with bar(total=target.chunks, initial=resumed, progress=progress, unit="chunk",
             desc=f"map (resumed: {resumed} chunks already in {out})" if resumed else "map") as shown:
        for c in todo:
            target.write(c, compute_chunk(robot, spec, centres, c))
            shown.update()
