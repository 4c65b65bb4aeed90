"""A library of analytic curves and surfaces, with exact level sets or closest-point functions,
triangulations for display and (where known) exact geodesic distances for testing.

Every surface here is a :class:`tubesweep.Surface` and can be passed straight to
:func:`tubesweep.solve`. Each has ``default_box`` (a cube, so ``Grid(*default_box, (N,)*d)`` is
uniform), ``default_source`` (a point on it) and ``triangulation(n) -> (V, F)`` (a polyline
``(V, segments)`` for curves); ``geodesic_distance(points, source)`` where an exact one exists.

========================  =================  ===============  =========================================
name (``REGISTRY``)       class              representation   exact geodesic distance
========================  =================  ===============  =========================================
``circle``                :class:`Circle`    φ (2D)           arclength
``star``                  :class:`Star`      φ (2D)           arclength (quadrature)
``ellipse``               :class:`Ellipse`   φ (2D)           arclength (quadrature)
``sphere``                :class:`Sphere`    φ                great circle
``ellipsoid``             :class:`Ellipsoid` φ                none (no closed form)
``torus``                 :class:`Torus`     φ                along the outer equator only
``rounded-cube``          :class:`RoundedCube` φ              none
``double-torus``          :class:`DoubleTorus` φ (genus 2)    none
``hemisphere``            :class:`Hemisphere` cp (open)       great circle
``disc``                  :class:`Disc`      cp (open)        Euclidean
``plane``                 :class:`PlanePatch` cp (open)       Euclidean
``mobius``                :class:`MobiusBand` cp (open, non-orientable)  none (tests use polyhedral geodesics)
========================  =================  ===============  =========================================

Point clouds: :func:`from_points` (samples or a point file → :class:`PointCloudSurface`, closest
points by moving least squares).

``REGISTRY`` maps the names used by the command line (``tubesweep solve --surface NAME``) to
factories that build the default instance.
"""

from typing import Callable, Dict

from ..surface import Surface
from .analytic import Circle, Sphere, Star
from .closed import DoubleTorus, Ellipsoid, RoundedCube, Torus
from .curves import Ellipse
from .mesh import MeshSurface, SmoothMeshSurface, from_mesh
from .open import Disc, Hemisphere, MobiusBand, PlanePatch
from .points import PointCloudSurface, from_points, read_points
from ._repr import give_repr

REGISTRY: Dict[str, Callable[[], Surface]] = {
    "circle": Circle,
    "star": Star,
    "ellipse": Ellipse,
    "sphere": Sphere,
    "ellipsoid": Ellipsoid,
    "torus": Torus,
    "rounded-cube": RoundedCube,
    "double-torus": DoubleTorus,
    "hemisphere": Hemisphere,
    "disc": Disc,
    "plane": PlanePatch,
    "mobius": MobiusBand,
}

give_repr(
    Circle, Star, Ellipse, Sphere, Ellipsoid, Torus, RoundedCube, DoubleTorus, Hemisphere, Disc, PlanePatch, MobiusBand
)

__all__ = [
    "Circle",
    "Star",
    "Ellipse",
    "Sphere",
    "Ellipsoid",
    "Torus",
    "RoundedCube",
    "DoubleTorus",
    "Hemisphere",
    "Disc",
    "PlanePatch",
    "MobiusBand",
    "MeshSurface",
    "SmoothMeshSurface",
    "from_mesh",
    "PointCloudSurface",
    "from_points",
    "read_points",
    "REGISTRY",
]
