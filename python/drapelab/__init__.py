"""drapelab from Python: simulate how fabric drapes, measure drape, fit photo edges, calibrate, and
run drapelab's pipelines, with NumPy arrays and dicts back.

Units are SI throughout and named in every key (``energy_J``, ``max_residual_N``, ``z_m``).
Positions are ``(n, 3)`` float64 arrays in metres in grid order ``j * nx + i``.

Bad input raises :class:`InputError` (a ``ValueError``) whose message names the file or argument
and the key, as the command line's exit code 2 does. A solve that does not converge is not an
exception: its :attr:`Result.status` says so (``"max-iterations"``, ``"diverged"``, ...). Long solves
release the GIL and stop on Ctrl-C (``KeyboardInterrupt``) within about 50 ms of an iteration.

>>> import drapelab
>>> r = drapelab.simulate("datasets/scenes/hang4.toml", overrides={"cloth.nx": 21, "cloth.ny": 21})
>>> r.status, r.positions.shape, r.grid().shape
('converged', (441, 3), (21, 21, 3))
"""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import tempfile
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _drapelab
from ._drapelab import InputError

__version__: str = _drapelab.version()

__all__ = [
    "InputError",
    "Result",
    "simulate",
    "simulate_many",
    "read_scene",
    "measure_drape",
    "measure_silhouette",
    "fit_edges",
    "calibrate",
    "run_pipeline",
]

PathLike = Union[str, "os.PathLike[str]"]

#: Every file a simulation may write into its folder (``drapelab simulate --out``).
SIMULATE_FILES = (
    "run.json",
    "iterations.parquet",
    "particles.parquet",
    "last_state.parquet",
    "triangles.parquet",
    "drape.obj",
    "timeline.mcap",
    "drape.rrd",
    "sensitivity.parquet",
)


def _plain(v: Any) -> Any:
    """JSON for values NumPy and pathlib hand out (numpy scalars and arrays, paths)."""
    if isinstance(v, os.PathLike):
        return os.fspath(v)
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    raise InputError(f"{v!r}: a {type(v).__name__} has no TOML form")


def _json(v: Any) -> str:
    return json.dumps(v, default=_plain)


class Result:
    """One solved scene: its status, final positions and report, and its files.

    Attributes:
        status: ``"converged"``, or why the solve stopped (``"max-iterations"``, ``"diverged"``,
            ``"stalled"``, ...); the positions of a solve that did not converge are its last state,
            never a result.
        positions: ``(n, 3)`` float64 array, m, grid order ``j * nx + i``; of a mesh sheet
            (``cloth.mesh``), the OBJ file's vertex order (then ``nx = n``, ``ny = 1``).
        present: ``(n,)`` bool array: False for particles outside the sheet's shape (a disc's
            corners), which take no part in the solve.
        triangles: ``(m, 3)`` int64 array of the sheet's triangles (indices into ``positions``):
            the grid's over its present particles, or the mesh's.
        nx, ny: particles along x and y.
        report: the solve's report (dict): ``iterations``, ``energy_J``, ``max_residual_N``,
            ``wall_time_s``, ``solver``, ``status``, ``globalization``, ...
        run: the whole ``run.json`` (report, scene with defaults, drape measures, self-contact).
        folder: where the files are until the result is garbage-collected; :meth:`save` keeps them.
    """

    def __init__(self, run_json: str, positions: bytes, present: bytes, triangles: bytes,
                 nx: int, ny: int, native_time_s: float,
                 sensitivities: Sequence[Tuple[str, bytes]] = (),
                 frames: Sequence[Tuple[int, Optional[float], bytes]] = (),
                 *, tmp: tempfile.TemporaryDirectory) -> None:
        self._tmp = tmp
        self._frames = frames
        self._sensitivities = {
            k: np.frombuffer(v, dtype="<f8").reshape(-1, 3).copy() for k, v in sensitivities
        }
        #: Seconds the call spent in Rust: scene loaded, solved, files written, arrays made.
        self.native_time_s = native_time_s
        self.folder = pathlib.Path(tmp.name)
        self.run: Dict[str, Any] = json.loads(run_json)
        self.report: Dict[str, Any] = self.run["report"]
        self.status: str = self.run["status"]
        self.positions = np.frombuffer(positions, dtype="<f8").reshape(-1, 3).copy()
        self.present = np.frombuffer(present, dtype=np.uint8).astype(bool)
        self.triangles = np.frombuffer(triangles, dtype="<u4").reshape(-1, 3).astype(np.int64)
        self.nx = nx
        self.ny = ny

    @property
    def neutral_modes(self) -> List[Dict[str, Any]]:
        """The rigid motions the converged drape is free to make (``run.json``'s
        ``neutral_modes``): each a dict with ``kind`` ("slide" or "turn"), ``axis``, a point
        ``through_m`` of a turn's axis and ``curvature_rel``. Empty when there are none (and for a
        state that is no converged static drape). A sensitivity is the one orthogonal to them."""
        return list(self.run.get("neutral_modes") or [])

    def sensitivity(self, key: str) -> np.ndarray:
        """How each particle of the converged drape moves per unit of the scene key ``key``
        (``simulate(..., sensitivity=[key])``): an ``(n, 3)`` float64 array dx*/dθ, m per unit of
        the key as the scene file writes it, rows as :attr:`positions`. The same numbers as
        ``sensitivity.parquet``.

        Raises:
            KeyError: ``key`` was not asked for.
            RuntimeError: the state has no sensitivities (not converged, not a minimum); the
                message says why.
        """
        if key in self._sensitivities:
            return self._sensitivities[key]
        asked = self.run.get("sensitivity") or {}
        if key not in asked.get("keys", []):
            raise KeyError(f"{key!r}: not asked for; pass simulate(..., sensitivity=[{key!r}])")
        raise RuntimeError(f"no sensitivities: {asked.get('reason')}")

    def gradient(self, dj_dx: np.ndarray, keys: Sequence[str]) -> Dict[str, float]:
        """dJ/dθ of a scalar measure J of the drape for each key, given ∂J/∂x (an ``(n, 3)`` array
        like :attr:`positions`): the sensitivities contracted with it (equal to one adjoint solve,
        which the Rust API ``sensitivity::Equilibrium::gradient`` does)."""
        g = np.asarray(dj_dx, dtype=float).reshape(-1, 3)
        return {k: float(np.sum(self.sensitivity(k) * g)) for k in keys}

    def grid(self) -> np.ndarray:
        """The positions as the grid they sit on: an ``(ny, nx, 3)`` view of :attr:`positions`,
        ``grid()[j, i]`` the particle in column ``i`` and row ``j`` (the centre is
        ``grid()[ny // 2, nx // 2]``)."""
        return self.positions.reshape(self.ny, self.nx, 3)

    def frames(self) -> Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]:
        """The solve's states as ``simulate(..., frames=K)`` kept them (at most K, evenly spaced
        over the Newton iterations or time steps, the first included): ``(x, index, t)`` with
        ``x`` an ``(frames, n, 3)`` float64 array (m, rows as :attr:`positions`), ``index`` the
        iteration or step of each and ``t`` its simulated time in s (None for a static solve).

        Raises:
            RuntimeError: no frames were asked for.
        """
        if not self._frames:
            raise RuntimeError("no frames: pass simulate(..., frames=200) to keep them")
        x = np.stack([np.frombuffer(b, dtype="<f8").reshape(-1, 3) for _, _, b in self._frames])
        index = np.array([i for i, _, _ in self._frames], dtype=np.int64)
        times = [t for _, t, _ in self._frames]
        t = None if any(v is None for v in times) else np.array(times, dtype=float)
        return x, index, t

    def to_pandas(self):
        """The particles (``i``, ``j``, ``x_m``, ``y_m``, ``z_m``, ``present``) as a pandas
        DataFrame, rows as :attr:`positions` (needs ``pandas``)."""
        import pandas as pd

        j, i = np.divmod(np.arange(self.nx * self.ny), self.nx)
        return pd.DataFrame({
            "i": i.astype(np.uint32), "j": j.astype(np.uint32),
            "x_m": self.positions[:, 0], "y_m": self.positions[:, 1], "z_m": self.positions[:, 2],
            "present": self.present,
        })

    @property
    def converged(self) -> bool:
        """Whether the solve converged (``status == "converged"``)."""
        return self.status == "converged"

    @property
    def scene(self) -> Dict[str, Any]:
        """The scene as solved, every default filled in."""
        return self.run["scene"]

    def table_path(self) -> pathlib.Path:
        """``particles.parquet`` (converged) or ``last_state.parquet`` (not converged)."""
        name = "particles.parquet" if self.converged else "last_state.parquet"
        path = self.folder / name
        if not path.exists():
            raise RuntimeError(f"no particle table: the solve ended {self.status}")
        return path

    def to_polars(self):
        """The particles table (``i``, ``j``, ``x_m``, ``y_m``, ``z_m``, ``present``) as a polars
        DataFrame (needs ``polars``)."""
        import polars as pl

        return pl.read_parquet(self.table_path())

    def save(self, folder: PathLike) -> pathlib.Path:
        """Writes the files ``drapelab simulate --out FOLDER`` writes (``run.json``,
        ``particles.parquet`` or ``last_state.parquet``, and ``timeline.mcap`` / ``drape.rrd`` when
        the scene records them) into ``folder``, ``run.json`` last; simulate files of an earlier run
        that this one did not write are removed, other files left alone. Returns the folder."""
        out = pathlib.Path(folder)
        out.mkdir(parents=True, exist_ok=True)
        written = [f for f in SIMULATE_FILES if (self.folder / f).exists()]
        for f in SIMULATE_FILES:
            if f not in written and (out / f).exists():
                (out / f).unlink()
        for f in sorted(written, key=lambda f: f == "run.json"):
            partial = out / f".{f}.partial"
            shutil.copyfile(self.folder / f, partial)
            os.replace(partial, out / f)
        return out

    def __repr__(self) -> str:
        r = self.report
        return (f"<drapelab.Result {self.run['scene'].get('name', '')!r}: {self.status}, "
                f"{self.nx}×{self.ny} particles, {r.get('iterations')} iterations, "
                f"residual {r.get('max_residual_N', float('nan')):.3g} N, "
                f"{r.get('wall_time_s', float('nan')):.3g} s>")


def read_scene(path: PathLike) -> Dict[str, Any]:
    """A scene TOML file as a dict (edit it and pass it to :func:`simulate`)."""
    return json.loads(_drapelab.read_scene(os.fspath(path)))


def simulate(scene: Union[PathLike, Mapping[str, Any]],
             overrides: Optional[Mapping[str, Any]] = None,
             sensitivity: Sequence[str] = (),
             frames: int = 0,
             progress: Optional[Callable[[int, Optional[float], float, float], Any]] = None,
             *, set: Optional[Mapping[str, Any]] = None,
             fabric: Optional[PathLike] = None,
             start: Optional[Union[PathLike, "Result"]] = None) -> Result:
    """Solves a scene as ``drapelab simulate`` does.

    Args:
        scene: a scene TOML file's path, or a dict with the same keys (``read_scene`` gives one).
        overrides: values by dotted key, e.g.
            ``{"cloth.nx": 21, "cloth.areal_density_kg_per_m2": 0.2}``; a grid override moves pins
            and holds to the same material points. (``set=`` is its old name, still taken.)
        sensitivity: continuous scene keys whose sensitivities dx*/dθ to compute at the converged
            drape (:meth:`Result.sensitivity`), e.g. ``["material.mass_spring.stiffness_N_per_m"]``.
        frames: keep up to this many states of the solve, evenly spaced (:meth:`Result.frames`);
            0 keeps none.
        progress: called as ``progress(index, time_s, max_residual_N, energy_J)`` at most every
            50 ms during the solve (``time_s`` None for a static solve); an exception it raises
            stops the solve and is raised again.
        fabric: a fabric file (as a calibration writes it) whose material, and areal density where
            it gives one, replace the scene's, as ``drapelab simulate --fabric FILE`` does.
        start: a saved drape to start from (a ``particles.parquet`` or ``last_state.parquet`` of
            the same scene, or a :class:`Result`), as ``drapelab simulate --start FILE`` does: the
            restart takes up what that run adapted (the self-contact κ growth) and continues it,
            so a converged drape at the same parameters comes back in 0 iterations.

    Returns:
        The :class:`Result`, converged or not (see its ``status``).

    Raises:
        InputError: an unknown key, a bad value or an unreadable file, named in the message.
        KeyboardInterrupt: Ctrl-C during the solve.
    """
    if set is not None and overrides is not None:
        raise InputError("set: give overrides= (its new name) or set=, not both")
    given = dict(overrides if overrides is not None else (set or {}))
    if fabric is not None:
        if not os.path.isfile(fabric):
            raise InputError(f"fabric: {os.fspath(fabric)} is not a file")
        given["material"] = {"fabric": os.path.abspath(fabric)}
    overrides_json = _json(given)
    if isinstance(scene, Mapping):
        path, table = None, _json(dict(scene))
    else:
        path, table = os.fspath(scene), None
    if not isinstance(frames, int) or frames < 0:
        raise InputError(f"frames: a count ≥ 0, got {frames!r}")
    start_path = None
    if start is not None:
        start_path = os.fspath(start.table_path() if isinstance(start, Result) else start)
    tmp = tempfile.TemporaryDirectory(prefix="drapelab-")
    try:
        out = _drapelab.simulate(path, table, overrides_json, tmp.name, list(sensitivity),
                                 frames, progress, start_path)
    except BaseException:
        tmp.cleanup()
        raise
    return Result(*out, tmp=tmp)


def simulate_many(scenes: Union[PathLike, Mapping[str, Any],
                                Sequence[Union[PathLike, Mapping[str, Any]]]],
                  overrides: Optional[Sequence[Mapping[str, Any]]] = None,
                  threads: Optional[int] = None, **kwargs: Any) -> List[Result]:
    """Solves several scenes at once, each as :func:`simulate` does, in parallel threads (the
    solves release the GIL): a list of scenes, or one scene under a list of overrides (a sweep), or
    both paired one to one. Results come back in order.

    Args:
        scenes: a scene (path or dict) or a list of them.
        overrides: a list of override dicts (one solve each).
        threads: how many solves at a time (default: the CPU count).
        **kwargs: passed to every :func:`simulate` (``sensitivity``, ``frames``).

    >>> rs = drapelab.simulate_many("datasets/scenes/hang4.toml",
    ...     overrides=[{"material.mass_spring.stiffness_N_per_m": k} for k in (600.0, 1100.0)])
    """
    single = isinstance(scenes, (str, os.PathLike, Mapping))
    scene_list = [scenes] if single else list(scenes)
    over = list(overrides) if overrides is not None else [None]
    if len(scene_list) == 1:
        scene_list = scene_list * len(over)
    elif len(over) == 1:
        over = over * len(scene_list)
    if len(scene_list) != len(over):
        raise InputError(f"overrides: {len(over)} for {len(scene_list)} scenes; give one per scene")
    if threads is not None and (not isinstance(threads, int) or threads < 1):
        raise InputError(f"threads: a count ≥ 1, got {threads!r}")
    with ThreadPoolExecutor(max_workers=threads or os.cpu_count() or 1) as pool:
        jobs = [pool.submit(simulate, s, o, **kwargs) for s, o in zip(scene_list, over)]
        return [j.result() for j in jobs]


def _measures(text: str) -> Dict[str, Any]:
    m = json.loads(text)
    radii = np.asarray(m["outline_m"], dtype=float)
    k = np.arange(radii.size)
    return {
        "drape_coefficient_pct": m["dc_pct"],
        "nodes": m["nodes"],
        "shadow_area_m2": m["area_m2"],
        "outline_radius_m": radii,
        "outline_angle_rad": (k + 0.5) * 2 * np.pi / max(radii.size, 1),
    }


def measure_drape(positions: Union[Result, np.ndarray],
                  triangles: Optional[np.ndarray] = None) -> Dict[str, Any]:
    """The Cusick drape tester's measures of a draped mesh's vertical projection: the drape
    coefficient (BS 5058, %, over the tester's 18 cm pedestal and 30 cm specimen), the nodes of its
    shadow's outline, the shadow's area (m²) and the smoothed outline r(θ) (m, 1° sectors).

    Args:
        positions: ``(n, 3)`` vertex positions in metres, centred on the pedestal's axis (z up), or a
            :class:`Result` (its present particles and grid triangles).
        triangles: ``(m, 3)`` vertex indices (not needed with a Result).
    """
    if isinstance(positions, Result):
        r = positions
        keep = r.present[r.triangles].all(axis=1)
        positions, triangles = r.positions, r.triangles[keep]
    if triangles is None:
        raise InputError("triangles: give the mesh's (m, 3) triangles")
    x = np.ascontiguousarray(positions, dtype="<f8")
    t = np.ascontiguousarray(triangles, dtype="<u4")
    if x.ndim != 2 or x.shape[1] != 3:
        raise InputError(f"positions: an (n, 3) array, got shape {x.shape}")
    return _measures(_drapelab.drape_of_mesh(x.tobytes(), t.tobytes()))


def measure_silhouette(photo: PathLike, *, px_per_m: float = 723.2,
                       centre_px: Sequence[float] = (126.95, 127.44),
                       threshold: int = 128) -> Dict[str, Any]:
    """The same measures of a Cusick silhouette photo (a dark shadow on a light ground).

    Args:
        photo: PNG or JPEG.
        px_per_m: the photo's scale, pixels per metre (default: the BDP dataset's 256² photos).
        centre_px: pixel (column, row) of the pedestal's centre.
        threshold: grey level below which a pixel is shadow.
    """
    scale = {"px_per_m": px_per_m, "centre_px": list(centre_px), "threshold": threshold}
    return _measures(_drapelab.drape_of_silhouette(os.fspath(photo), _json(scale)))


def fit_edges(photo: PathLike, camera: Optional[PathLike] = None,
              degree: int = 4) -> List[Dict[str, Any]]:
    """The edges of a hanging-fabric photo fitted with polynomials (seed 000 Figs 11-12).

    Args:
        photo: PNG or JPEG.
        camera: its ``camera.json`` (as ``drapelab render`` writes it); default: beside the photo.
        degree: polynomial degree (seed 000: 4).

    Returns:
        One dict per edge: ``edge``, ``coefficients`` (of x⁰…x^degree, x and y in cm),
        ``rms_residual_cm``, ``n_points``, ``x_min_cm``, ``x_max_cm``, ``systematic_pct``, ...
    """
    photo = pathlib.Path(photo)
    cam = pathlib.Path(camera) if camera is not None else photo.parent / "camera.json"
    return json.loads(_drapelab.fit_edges(str(photo), str(cam), degree))


def calibrate(edges: PathLike, sample: str, *, samples: PathLike, scene: PathLike,
              ica: Optional[Mapping[str, Any]] = None, optimizer: str = "ica",
              **params: Any) -> Dict[str, Any]:
    """One sample calibrated against its measured edges, as a ``calibrate`` stage does for each
    sample, without writing files: by ICA (seed 000, ``optimizer="ica"``) or by gradients
    (``optimizer="levenberg-marquardt"``: Levenberg–Marquardt over stiffness and natural length per
    topology, its Jacobian from the drapes' sensitivities; a few dozen solves instead of thousands,
    no ``ica`` needed).

    Args:
        edges: a fit-edges table (``edges.parquet``).
        sample: the sample's name in it (its photo's folder, e.g. ``"datasets/knitted/sample_03/hang4"``).
        samples: the samples table with their densities (``datasets/knitted/knitted_samples.csv``).
        scene: the net's scene (``datasets/scenes/hang4.toml``).
        ica: ICA's settings (seed 000 Table 1): ``decades``, ``countries``, ``imperialists``,
            ``beta``, ``gamma`` (rad), ``revolution_rate``, ``xi``, ``seed``; required by ``"ica"``.
        optimizer: ``"ica"`` (default) or ``"levenberg-marquardt"``.
        params: the calibrate stage's other parameters (``runs``, ``grid``, ``side_cm``,
            ``polish_iterations``, ...; ``drapelab kinds`` lists them with defaults).

    Returns:
        ICA: the results row (calibrated stiffness in N/m, natural length in m, the runs' spread and
        each parameter's identifiability). Levenberg–Marquardt: ``topology``,
        ``stiffness_N_per_m``, ``natural_length_m``, ``curve_distance_pct``, ``solves``, ``steps``,
        ``stop``.
    """
    files = (os.fspath(edges), os.fspath(samples), os.fspath(scene))
    if optimizer == "levenberg-marquardt":
        return json.loads(_drapelab.calibrate_lm(*files, sample, _json(dict(params))))
    if optimizer != "ica":
        raise InputError(f"optimizer: `{optimizer}` is not one of \"ica\", \"levenberg-marquardt\"")
    if ica is None:
        raise InputError("ica: ICA's settings are required by optimizer \"ica\"")
    p = dict(params, ica=dict(ica))
    return json.loads(_drapelab.calibrate(*files, sample, _json(p)))


def run_pipeline(path: PathLike, until: Optional[str] = None,
                 force: Optional[Sequence[str]] = None,
                 progress: Optional[Callable[[str, str, int, int], Any]] = None) -> Dict[str, Any]:
    """Runs a pipeline make-style, as ``drapelab run`` does: only stale stages run.

    Args:
        path: the pipeline file (``pipelines/main.toml``); paths in it are relative to the project
            root, the folder above ``pipelines/`` (else the file's own folder), wherever Python runs,
            as for the command line.
        until: run only this stage and what it depends on.
        force: rerun these stages and their dependents even when up to date.
        progress: called as ``progress(stage, event, done, total)`` with event ``"started"``,
            ``"item"`` (one of a stage's ``total`` items done), ``"finished"`` or ``"skipped"``;
            an exception it raises is raised when the run ends.

    Returns:
        ``{"pipeline", "run_dir", "ran": [...], "up_to_date": [...], "failed": {stage: why}, "ok"}``.
    """
    return json.loads(_drapelab.run_pipeline(os.fspath(path), until, list(force or []), progress))
