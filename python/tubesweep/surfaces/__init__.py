"""A library of analytic curves and surfaces with exact level sets, and (where known) exact
geodesic distances for testing.

Every surface here is a :class:`tubesweep.Surface` and can be passed straight to
:func:`tubesweep.solve`. ``REGISTRY`` maps the names used by the command line
(``tubesweep solve --surface NAME``) to factories.
"""

from .analytic import Circle, Sphere, Star, REGISTRY
from .mesh import from_mesh, MeshSurface

__all__ = ["Circle", "Sphere", "Star", "REGISTRY"]
