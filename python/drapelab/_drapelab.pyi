"""Type stubs of drapelab's native module (crates/python): plain values in and out; the public API is
`drapelab` itself, which wraps these into NumPy arrays, dicts and `Result`."""

from typing import Any, Callable, List, Optional, Tuple

class InputError(ValueError):
    """Bad input: the message names the file (or argument) and the key."""

def version() -> str: ...
def read_scene(path: str) -> str: ...
def simulate(
    scene_path: Optional[str],
    scene_json: Optional[str],
    set_json: str,
    out: str,
    sensitivity: List[str] = ...,
    frames: int = ...,
    progress: Optional[Callable[[int, Optional[float], float, float], Any]] = ...,
    start: Optional[str] = ...,
) -> Tuple[str, bytes, bytes, bytes, int, int, float, List[Tuple[str, bytes]],
           List[Tuple[int, Optional[float], bytes]]]:
    """run.json's text, positions (n×3 little-endian f64, m), present (n bytes), triangles
    (m×3 little-endian u32), nx, ny, seconds spent in Rust, per key asked for its
    sensitivities (n×3 little-endian f64, m per unit of the key), and the frames kept
    (iteration or step, simulated time or None, n×3 little-endian f64, m)."""

def drape_of_mesh(positions: bytes, triangles: bytes) -> str: ...
def drape_of_silhouette(path: str, scale_json: str) -> str: ...
def fit_edges(photo: str, camera: str, degree: int) -> str: ...
def calibrate(edges: str, samples: str, scene: str, sample: str, params_json: str) -> str: ...
def calibrate_lm(edges: str, samples: str, scene: str, sample: str, params_json: str) -> str: ...
def run_pipeline(path: str, until: Optional[str], force: List[str],
                 progress: Optional[Callable[[str, str, int, int], Any]] = ...) -> str: ...
