"""Many sources on a Dask cluster: :meth:`Tube.solve_many` and :func:`distance_matrix` with
``client=`` (``pip install 'tubesweep[distributed]'``, or ``pip install '.[distributed]'`` in a checkout).

The sources are split into chunks, one Dask task each. The tube goes to every worker once, as a
small description (its surface, grid and widths: no band arrays), scattered with ``broadcast``;
each worker process builds the band from it on its first chunk and keeps it in a cache keyed by
the tube's token (:data:`_WORKER_TUBES`), so that its later chunks reuse it. A task returns only
its rows: the values at ``at`` (or, without ``at``, the chunk's band values). Each row is computed
by the same code as locally (``Tube.solve_many`` on the worker, one thread per solve), so the
result equals the local one bit for bit.

A worker that dies mid-run loses its running chunks; the scheduler runs them again elsewhere
(up to its ``distributed.scheduler.allowed-failures``), and the result is complete. Workers that
all die at once take the scattered inputs with them: those are scattered again and the cancelled
chunks resubmitted, as many times. When a chunk cannot be completed the call raises
``RuntimeError`` naming the sources of the chunk (a ``ValueError`` or ``TypeError`` raised on a
worker keeps its type): a partial matrix is never returned.
"""

from __future__ import annotations

import math
import threading
import uuid
from concurrent.futures import CancelledError
from collections import OrderedDict
from typing import TYPE_CHECKING, Any, Callable, Dict, List, Optional

import numpy as np

from ._chunk_messages import merged
from ._validate import as_points, check_flag, check_threads, speed_values
from .many import check_many_progress, fixed_nodes, solve_many, source_groups

if TYPE_CHECKING:  # pragma: no cover
    from .tube import Tube

__all__ = ["solve_many_on_client", "clear_worker_cache"]

#: Tubes a worker process keeps, most recently used last (the bands of the last two tubes).
WORKER_CACHE_SIZE = 2
_WORKER_TUBES: "OrderedDict[str, Tube]" = OrderedDict()
_WORKER_LOCK = threading.Lock()


class _TubeSpec:
    """What a worker needs to build a tube: the surface, grid and widths (a pickled ``Tube``
    would build its band on unpickling, once per task that receives it)."""

    def __init__(self, tube: "Tube"):
        self.token = tube._token
        self.cls = type(tube)  # the class travels by name: this module need not import tube.py
        self.surface = tube.surface
        self.grid = tube.grid
        self.args = tube._args


def _worker_tube(spec: _TubeSpec) -> "Tube":
    """The tube of ``spec`` in this process, built on first use and cached by its token."""
    with _WORKER_LOCK:  # one build per process, even with several threads per worker
        tube = _WORKER_TUBES.get(spec.token)
        if tube is None:
            inner, outer, method = spec.args
            tube = spec.cls(spec.surface, spec.grid, inner=inner, outer=outer, method=method)
            tube._token = spec.token
            _WORKER_TUBES[spec.token] = tube
            while len(_WORKER_TUBES) > WORKER_CACHE_SIZE:
                _WORKER_TUBES.popitem(last=False)
        _WORKER_TUBES.move_to_end(spec.token)
        return tube


#: At most this many warnings from the workers, each said once (the last one counts the rest).
WORKER_WARNINGS = 5

#: The stats of a batch that are the tube's (the same for every chunk), sent back with the rows.
_TUBE_STATS = ("first_order_nodes", "inner_nodes", "first_order_reasons", "creases", "max_curvature", "grad_norm_range")


def _solve_chunk(
    spec: _TubeSpec, groups: List[np.ndarray], at: Optional[np.ndarray], options: Dict[str, Any], number_from: int = 0
) -> Any:
    """One task: the chunk's sources on the worker's cached tube, one solve per thread;
    ``number_from``: the chunk's first source's place among all (for the messages)."""
    import warnings

    tube = _worker_tube(spec)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # (the local solve_many: the client's Tube.solve_many names the points of at off the band, once)
        values, stats = solve_many(
            tube, groups, at=at, threads=1, return_stats=True, number_from=number_from, **options
        )
    return (
        values,
        {k: v for k, v in stats.items() if isinstance(v, np.ndarray) or k in _TUBE_STATS},
        [str(w.message) for w in caught],
        stats.get("order_fallback"),
    )


def _clear() -> int:
    with _WORKER_LOCK:
        n = len(_WORKER_TUBES)
        _WORKER_TUBES.clear()
    return n


def clear_worker_cache(client: Any) -> Dict[str, int]:
    """Drops the tubes the workers of ``client`` keep (returns how many each held)."""
    return client.run(_clear)


def as_client(client: Any) -> Any:
    """``client`` checked to be a ``dask.distributed.Client``."""
    try:
        from distributed import Client
    except ImportError:
        raise ImportError(
            "client= needs Dask's distributed scheduler (dask, distributed and cloudpickle): "
            "pip install 'tubesweep[distributed]', or pip install '.[distributed]' in a checkout"
        ) from None
    if not isinstance(client, Client):
        raise TypeError(
            f"client must be a dask.distributed.Client (e.g. Client(LocalCluster()) or "
            f"Client('tcp://scheduler:8786')); got {type(client).__name__}"
        )
    return client


def _check_sendable(options: Dict[str, Any]) -> None:
    """A callable option (a speed, a flow) that cloudpickle cannot serialise, named before anything
    is sent (Dask's own error came after a hundred lines of its serialiser's traceback)."""
    import cloudpickle

    for name, value in options.items():
        if callable(value):
            try:
                cloudpickle.dumps(value)
            except Exception as e:
                raise TypeError(
                    f"{name}: cannot be sent to the Dask workers ({type(e).__name__}: {e}); pass a function that "
                    "holds no locks, open files or connections (or solve on this machine: client=None)"
                ) from None


def _default_chunk(k: int, workers: int) -> int:
    # about four chunks per worker thread (the last ones balance the load), at most 64 sources each
    return max(1, min(64, math.ceil(k / (4 * max(1, workers)))))


def solve_many_on_client(
    tube: "Tube",
    sources: Any,
    *,
    client: Any,
    at: Any,
    chunk_size: Optional[int],
    progress: Optional[Callable[[int, int], Any]],
    options: Dict[str, Any],
    threads: int = 0,
    return_stats: bool = False,
) -> Any:
    """:meth:`Tube.solve_many` on a Dask cluster (see the module's documentation). ``threads`` is
    not used: each worker runs as many chunks at once as it has threads, one thread per solve."""
    from dask.config import get as dask_config_get
    from distributed import as_completed

    client = as_client(client)
    tube._check_phi_unchanged()
    groups = source_groups(sources, tube.grid.ndim)
    k = len(groups)
    check_flag(return_stats, "return_stats")
    if k == 0:
        raise ValueError("sources is empty: give at least one source (a point, or a group of points)")
    cb = check_many_progress(progress)
    check_threads(threads)  # (not used: checked as a local solve_many checks it)
    speed = options.get("speed", 1.0)
    if not callable(speed):  # a number or an array of grid.shape, checked as locally (a callable runs on the workers)
        linear = tube._tube.linear
        speed_values(speed, tube.grid, np.empty((len(linear), 0)), linear)
    points = None if at is None else as_points(at, tube.grid.ndim, "at")
    # every source checked here, before anything is sent: a bad one is refused with its index
    fixed_nodes(tube, groups, options.get("speed", 1.0), options.get("source_init", "exact"))
    if getattr(client, "status", "running") in ("closed", "closing", "failed"):
        raise ValueError(
            f"client: this Dask client is {client.status}; connect a new one (Client(cluster) or "
            "Client('tcp://scheduler:8786')) or leave client=None to solve on this machine"
        )
    nthreads = sum(client.nthreads().values())
    if nthreads == 0:
        raise RuntimeError(
            "the Dask cluster has no workers: start some (e.g. LocalCluster(n_workers=2)) or wait for them"
        )
    if chunk_size is None:
        chunk_size = _default_chunk(k, nthreads)
    if not (isinstance(chunk_size, (int, np.integer)) and not isinstance(chunk_size, bool) and chunk_size >= 1):
        raise ValueError(f"chunk_size must be a positive whole number of sources per task; got {chunk_size!r}")
    starts = list(range(0, k, int(chunk_size)))
    _check_sendable(options)
    run = uuid.uuid4().hex[:12]
    width = tube.band_points if points is None else len(points)
    out = np.empty((k, width))
    stats: Dict[str, np.ndarray] = {}
    tube_stats: Dict[str, Any] = {}
    messages: List[str] = []
    reasons: List[str] = []  # why some rows ran the first-order scheme (order="auto"), per chunk
    done = 0
    pending = starts
    # rounds of the chunks whose shared inputs were lost: the tube, at and the options are
    # scattered, and when every worker that held them died (each once, an out-of-memory kill) the
    # scheduler cannot compute them again and cancels the chunks that need them ("already
    # forgotten"); they are scattered again and those chunks resubmitted, as often as the
    # scheduler would rerun a chunk whose worker died
    rounds = 1 + int(dask_config_get("distributed.scheduler.allowed-failures", 3))
    for round_ in range(rounds):
        spec = client.scatter(_TubeSpec(tube), broadcast=True, hash=False)
        at_data = None if points is None else client.scatter(points, broadcast=True, hash=False)
        # the options go once too: a speed given as an array of the grid's shape is as large as a φ array
        opts = client.scatter([options], broadcast=True, hash=False)[0]
        futures = {
            client.submit(
                _solve_chunk,
                spec,
                groups[a : a + chunk_size],
                at_data,
                opts,
                a,
                key=f"tubesweep-solve_many-{run}-{round_}-{a}",
                pure=False,
            ): a
            for a in pending
        }
        lost: List[int] = []
        try:
            for fut in as_completed(futures):
                a = futures[fut]
                b = min(a + chunk_size, k)
                try:
                    values, st, caught, chunk_reason = fut.result()
                except (ValueError, TypeError, KeyboardInterrupt):
                    raise
                except CancelledError:  # its shared inputs lost with the workers that held them
                    lost.append(a)
                    continue
                except Exception as e:  # a worker that died on every try (KilledWorker)...
                    raise RuntimeError(
                        f"the Dask cluster could not solve sources {a}..{b - 1}: {type(e).__name__}: {e}. "
                        "No partial result is returned; check the workers' logs and memory "
                        "(docs/many-sources.md, 'What to size')"
                    ) from e
                out[a:b] = values
                if chunk_reason is not None:
                    reasons.append(chunk_reason)
                for name, v in st.items():
                    if not isinstance(v, np.ndarray):
                        tube_stats.setdefault(name, v)  # the tube's: the same from every chunk
                        continue
                    stats.setdefault(name, np.empty(k, dtype=v.dtype))[a:b] = v
                messages.extend(caught)
                done += b - a
                if cb is not None:
                    cb(done, k)
        finally:
            client.cancel(list(futures))
            del spec, at_data, opts
        if not lost:
            break
        pending = sorted(lost)
    else:
        a = pending[0]
        raise RuntimeError(
            f"the Dask cluster could not solve sources {a}..{min(a + chunk_size, k) - 1} (and {len(pending) - 1} more "
            f"chunks): the workers holding the shared inputs (the tube, at, the options) died {rounds} times over, "
            "taking them along. No partial result is returned; check the workers' logs and memory "
            "(docs/many-sources.md, 'What to size')"
        )
    messages = merged(messages, k)  # (in the order the chunks came back)
    if messages:
        import warnings

        # each once, as the batch on this machine says them; a few at most
        for i, message in enumerate(messages[:WORKER_WARNINGS]):
            more = len(messages) - WORKER_WARNINGS if i == WORKER_WARNINGS - 1 else 0
            warnings.warn(
                f"on the workers: {message}" + (f" (and {more} more)" if more > 0 else ""),
                RuntimeWarning,
                stacklevel=3,
            )
    if return_stats:
        stats_out: Dict[str, Any] = {**tube_stats, **stats}
        # each row's order; "order" the lowest, as locally (chunks may differ where a source ran away)
        stats_out["order"] = int(np.min(stats["orders"]))
        stats_out["order_fallback"] = "; ".join(merged(reasons, k)) if reasons else None
        return out, stats_out
    return out
