"""Reachability maps: which voxels of an arm's workspace it reaches, in how many orientations, how well.

- :mod:`~kinelab.maps.grid`: the voxel grid and the orientations spread over SO(3) (or over the sphere of
  tool axes).
- :mod:`~kinelab.maps.chunk`: one chunk of the map, a pure function of (robot, spec, chunk index).
- :mod:`~kinelab.maps.reach`: the whole map, in this process or on Dask (:mod:`~kinelab.maps.cluster`).
- :mod:`~kinelab.maps.base`: inverse reachability of a mobile base; :mod:`~kinelab.maps.singular`: σ over
  joint space.
- :mod:`~kinelab.maps.store`: the map on disk (Zarr), its metadata, and resuming an interrupted run.
- :mod:`~kinelab.maps.batch`: the same chunked, resumable way for a batch of IK targets on a Dask cluster.
"""

from kinelab.maps.base import BaseMap, base_map
from kinelab.maps.chunk import MapSpec
from kinelab.maps.reach import reachability
from kinelab.maps.singular import SingularityMap, singularity
from kinelab.maps.store import ReachabilityMap, load

__all__ = ["BaseMap", "MapSpec", "ReachabilityMap", "SingularityMap", "base_map", "load", "reachability",
           "singularity"]
