"""heron: a physically faithful spectral ray tracer for optics research, from Python.

Scenes are heron's TOML scene files (``load_scene``) or the same schema as a dict
(``Scene.from_dict``); ``Scene.render`` returns numpy arrays (linear sRGB, CIE XYZ,
spectral bins) equal bit for bit to the EXR ``heron render`` writes for the same
settings. ``trace``, ``sky_profile``, ``color`` and ``ior`` are the CLI's ``heron trace``,
``heron sky profile``, ``heron color`` and the scene files' refractive indices;
``compare`` is ``heron compare``; ``lens`` is ``heron lens``.

Bad input raises ``HeronError`` (a ``ValueError``) with the CLI's one-line message; where
the CLI names a flag (``--lanes``) the message names the argument (``lanes``).
"""

import os
from typing import Any, Literal, Mapping, NotRequired, Optional, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str
"""The crate version with the git commit heron was built from as a PEP 440 local label:
``0.1.0+g<40 hex>``, ``.dirty`` appended when its sources differed from that commit, plain
``0.1.0`` when built outside a git checkout."""
__commit__: str
"""The commit as the EXR provenance's ``heron.commit`` records it: 40 hex digits,
``-dirty`` appended when the sources differed, or ``unknown``."""

_Numbers = Union[float, Sequence[float], npt.NDArray[np.floating[Any]]]
_Path = Union[str, os.PathLike[str]]

class HeronError(ValueError):
    """Bad input (a scene key, an argument, a file): the heron CLI's one-line message."""

class Scene:
    """A loaded, validated heron scene (immutable; render it as often as you like)."""

    @staticmethod
    def from_dict(d: Mapping[str, Any]) -> "Scene":
        """A scene from a dict with the schema of heron's TOML scene files.

        The dict becomes TOML text and goes through the same loader as a file, so the
        checks and error messages are the loader's; they name the file ``<dict>``.
        Relative paths (meshes, tables) start at the current directory.
        """
    @property
    def width(self) -> int:
        """Image width in pixels."""
    @property
    def height(self) -> int:
        """Image height in pixels."""
    @property
    def spp(self) -> int:
        """The scene's ``[render] spp`` (the default of ``render``)."""
    @property
    def seed(self) -> int:
        """The scene's ``[render] seed`` (the default of ``render``)."""
    @property
    def integrator(self) -> str:
        """The scene's integrator (``[render] integrator``, default whitted)."""
    @property
    def materials(self) -> list[str]:
        """The material names, in the order of the file."""
    def render(
        self,
        spp: Optional[int] = None,
        seed: Optional[int] = None,
        lanes: Literal[1, 4, 8] = 8,
        integrator: Optional[Literal["whitted", "path", "lighttrace", "bdpt", "sppm"]] = None,
        wavelengths: Literal["visible", "uniform"] = "visible",
        threads: int = 0,
        spectral_bins: int = 0,
        sampler: Optional[Literal["sobol", "independent"]] = None,
        max_depth: Optional[int] = None,
        offset: Optional[Literal["auto", "epsilon", "robust"]] = None,
        variance: bool = False,
        packets: Optional[Literal["auto", "paths", "camera", "off"]] = None,
        medium_nee: Optional[Literal["forced", "collision"]] = None,
        sun_guide: Optional[float] = None,
        sppm_photons: Optional[int] = None,
        sppm_alpha: Optional[float] = None,
        sppm_radius: Optional[float] = None,
        polarization: Optional[bool] = None,
        polarizer: Optional[float] = None,
        hide_emitters: Optional[bool] = None,
        filter: Optional[str] = None,
    ) -> "RenderResult":
        """Renders the scene with ``heron render``'s options and defaults.

        spp and seed default to the scene's ``[render]`` values; threads 0 is one per
        core (the image does not depend on it); spectral_bins 0 is none, else 1-470
        equal bins over 360-830 nm; variance=True also estimates each pixel's variance
        (``heron render --variance``, at least 2 spp); packets chooses how rays go to
        Embree (``--packets``); medium_nee ("forced" or "collision") and sun_guide (a
        fraction in [0, 1)) choose the path tracer's estimators in media
        (``--medium-nee``, ``--sun-guide``); integrator "sppm" is stochastic
        progressive photon mapping (spp: its iterations) with sppm_photons,
        sppm_alpha and sppm_radius (``--sppm-photons``, ``--sppm-alpha``,
        ``--sppm-radius``); polarization=True renders Stokes vectors (``--polarization``;
        None keeps the scene's ``[render] polarization``) into ``RenderResult.stokes``;
        polarizer puts an analyser at that many degrees in front of the camera
        (``--polarizer``, over the scene's ``[camera] polarizer``); hide_emitters=True
        makes emitters seen directly by the camera black (``--hide-emitters``; None
        keeps the scene's ``[render] hide_emitters``); filter is the pixel
        reconstruction filter (``--filter``, e.g. "gaussian" or
        "mitchell:b=0,c=0.5"; None keeps the scene's ``[render] filter``).
        The GIL is released while
        rendering; Ctrl-C stops the render within a row of a tile and raises
        KeyboardInterrupt.
        """

class RenderResult:
    """The image and statistics of ``Scene.render``."""

    @property
    def rgb(self) -> npt.NDArray[np.float32]:
        """Linear sRGB, H x W x 3 (the EXR's R, G, B), row 0 at the top."""
    @property
    def xyz(self) -> npt.NDArray[np.float32]:
        """CIE 1931 XYZ, H x W x 3 (the EXR's X, Y, Z)."""
    @property
    def spectral(self) -> Optional[npt.NDArray[np.float32]]:
        """Mean spectral radiance per bin, H x W x bins (the EXR's S0.* channels), or None."""
    @property
    def wavelengths(self) -> Optional[npt.NDArray[np.float32]]:
        """The spectral bins' centres in nm, or None."""
    @property
    def variance(self) -> Optional[npt.NDArray[np.float32]]:
        """The variance of each pixel's R, G, B (of its mean), H x W x 3 (the EXR's
        variance.R, .G, .B), or None without variance=True."""
    @property
    def stokes(self) -> Optional[npt.NDArray[np.float32]]:
        """Stokes vectors in linear sRGB, H x W x 4 x 3: [..., k, c] is S_k of channel c,
        in the camera's frame (S1 > 0 horizontal, S2 > 0 at +45° counter-clockwise, S3 > 0
        right-circular; the EXR's R, G, B and S1.R ... S3.B), or None unpolarised."""
    @property
    def stokes_spectral(self) -> Optional[npt.NDArray[np.float32]]:
        """Stokes vectors per spectral bin, H x W x 4 x bins: [..., k, b] is S_k's mean
        spectral radiance in bin b (the EXR's S0.* ... S3.* channels; [..., 0, :] is
        `spectral`), or None without polarization or spectral bins."""
    spp: int
    """Samples per pixel in the image."""
    rays: int
    """All rays traced: camera and continued rays plus shadow rays."""
    camera_rays: int
    """Closest-hit rays: camera rays and the rays that continue paths."""
    shadow_rays: int
    """Occlusion (shadow) rays."""
    nonfinite_samples: int
    """Samples whose radiance was NaN or infinite, left out of the image."""
    wall_seconds: float
    """Wall-clock seconds of the render."""
    mrays_per_s: float
    """Million rays per second."""
    kernel: str
    """The kernel that ran, as the CLI names it."""
    integrator: str
    """whitted, path, lighttrace or bdpt."""
    lanes: int
    """Wavelengths per path: 1, 4 or 8."""
    sampler: str
    """sobol or independent."""
    seed: int
    """The seed of the render."""
    width: int
    """Image width in pixels."""
    height: int
    """Image height in pixels."""

def load_scene(path: _Path) -> Scene:
    """Reads and validates a scene file (heron's TOML, or a Mitsuba 3 .xml or pbrt-v4 .pbrt scene converted as ``heron convert`` does), as ``heron render SCENE`` does."""

class TraceEvent(TypedDict):
    kind: Literal["reflect", "refract", "total-internal-reflection", "absorb", "escape"]
    position: list[float]
    normal: Optional[list[float]]
    material: Optional[str]
    n_i: Optional[float]
    n_t: Optional[float]
    incoming: list[float]
    outgoing: Optional[list[float]]
    fresnel_r: Optional[float]
    distance: Optional[float]
    stokes: NotRequired[list[float]]
    stokes_x: NotRequired[list[float]]

def trace(
    scene: Union[Scene, _Path],
    origin: _Numbers,
    direction: _Numbers,
    wavelength: float,
    path: Optional[str] = None,
    stokes: Optional[_Numbers] = None,
) -> list[TraceEvent]:
    """Follows one ray at one wavelength through a scene, as ``heron trace`` does.

    path: R and T letters; at the k-th event at a surface that both reflects and
    transmits, R reflects and T transmits (default and past the end: transmit; total
    internal reflection forces R). "TRT" is the primary rainbow ray of a drop.
    stokes: (S0, S1, S2, S3) to start from, as ``heron trace --stokes``; each event then
    has ``stokes`` (after it, power) and ``stokes_x`` (its frame's x axis).
    """

def sky_profile(
    model: Literal["constant", "aristotle", "descartes", "airy", "mie"],
    wavelengths: _Numbers,
    theta: _Numbers,
    *,
    sun_radius: float = 0.2666,
    droplet_radius: Optional[float] = None,
    k: Optional[Union[int, str]] = None,
    polarisation: Optional[Literal["unpolarised", "s", "p"]] = None,
    background: Optional[float] = None,
    drops: Optional[dict[str, Any]] = None,
    debye: Optional[int] = None,
) -> npt.NDArray[np.float32]:
    """Radiance against the angle theta (degrees) from the antisolar point, as
    ``heron sky profile``: len(theta) rows by len(wavelengths) columns. drops (airy,
    mie): a drop-size distribution as the scene files' ``[sky] drops`` table;
    debye (mie): only Debye term p."""

def halo_profile(
    sun_elevation: float,
    crystals: list[dict[str, Any]],
    wavelengths: _Numbers,
    theta: _Numbers,
    *,
    psi: Optional[_Numbers] = None,
    sun_radius: float = 0.2666,
    rays: Optional[int] = None,
    seed: Optional[int] = None,
) -> npt.NDArray[np.float32]:
    """The halo sky's radiance per unit solar irradiance (sr⁻¹) against the angle theta
    (degrees) from the sun along great circles at position angles psi (default 0, 90,
    180), as ``heron halo profile``: len(theta) × len(psi) × len(wavelengths). crystals:
    populations as the scene files' ``[sky] crystals`` tables."""

class Color(TypedDict):
    XYZ: list[float]
    xy: Optional[list[float]]
    linear_srgb: list[float]
    observer: str
    illuminant: str
    interpolation: str

def color(
    wavelengths: _Numbers,
    values: _Numbers,
    illuminant: Literal["D65", "D50", "A", "E", "none"] = "D65",
    observer: Union[Literal["1931", "1964"], int] = "1931",
    interpolation: Literal["cie167", "linear"] = "cie167",
) -> Color:
    """XYZ, xy and linear sRGB of a spectral distribution, as ``heron color``."""

def ior(
    model: Union[str, float, Mapping[str, Any]],
    wavelengths: _Numbers,
) -> npt.NDArray[np.float32]:
    """n(lambda) of a refractive-index model given as a scene file's ``ior`` value."""

_Image = Union[
    _Path,
    RenderResult,
    npt.ArrayLike,
    tuple[npt.ArrayLike, npt.ArrayLike],
]

class RegionTest(TypedDict):
    x: int
    y: int
    width: int
    height: int
    channel: int
    pixels: int
    mean_a: float
    mean_b: float
    difference: float
    standard_error: float
    z: float
    p: float
    degrees_of_freedom: Optional[float]
    fails: bool
    whole_image: bool

class Comparison(TypedDict):
    same: bool
    status: Literal[0, 1]
    report: str
    tests: int
    width: int
    height: int
    channels: list[str]
    region: int
    alpha: float
    correction: Literal["sidak", "bonferroni"]
    tolerance: float
    variance_from: Literal["channels", "spread"]
    per_test_alpha: float
    critical_z: float
    critical_t: Optional[float]
    rel_rmse: float
    rel_mse: float
    mean_difference: list[float]
    standard_error: list[float]
    failing: list[RegionTest]
    regions: list[RegionTest]
    whole: list[RegionTest]
    identical: int
    z: npt.NDArray[np.float64]

def compare(
    a: _Image,
    b: _Image,
    *,
    region: int = 16,
    alpha: float = 0.01,
    correction: Literal["sidak", "bonferroni"] = "sidak",
    mask: Optional[npt.ArrayLike] = None,
    tolerance: float = 0.0,
    heatmap: Optional[_Path] = None,
) -> Comparison:
    """Are two renders the same image up to noise? ``heron compare``'s region z-test.

    a, b: an EXR path, a RenderResult, an H x W x 3 array, or (array, variance array);
    b is the reference of the relative errors. Standard errors come from both images'
    variance, else from the spread within each region (Student t); tolerance is a
    relative margin within which mean differences are allowed (sppm's radius bias).
    "same" is the
    verdict and "status" the CLI's exit status (0 same, 1 different); errors raise
    HeronError (the CLI's status 2).
    """

class LensParaxial(TypedDict):
    """First order at one wavelength: the columns of ``heron lens``'s paraxial.csv.
    Lengths in mm; pupil positions from the first (entrance) and last (exit) vertex,
    positive toward the image."""

    wavelength_nm: float
    efl_mm: float
    bfl_mm: float
    f_number: float
    entrance_pupil_z_mm: float
    entrance_pupil_diameter_mm: float
    exit_pupil_z_mm: float
    exit_pupil_diameter_mm: float

class LensFocalShift(TypedDict):
    """The columns of focal_shift.csv as arrays of 61 values, 400-700 nm every 5 nm."""

    wavelength_nm: npt.NDArray[np.float64]
    bfl_mm: npt.NDArray[np.float64]
    focal_shift_mm: npt.NDArray[np.float64]
    """BFL(lambda) - BFL(reference wavelength)."""

class LensSpot(TypedDict):
    """One field angle at one wavelength: the columns of spots.csv, and the points."""

    field_deg: float
    wavelength_nm: float
    rays: int
    """Rays that reached the image plane."""
    rms_radius_mm: float
    geo_radius_mm: float
    centroid_x_mm: float
    centroid_y_mm: float
    vignetted_fraction: float
    """Share of the traced rays a rim or the stop would stop."""
    points_mm: npt.NDArray[np.float64]
    """rays x 2: each ray's (x, y) in the reference wavelength's paraxial image plane
    (spot_points.csv writes them minus the centroid)."""

class LensReport(TypedDict):
    name: str
    reference_wavelength_nm: float
    paraxial: list[LensParaxial]
    """At the F, d and C lines (486.1327, 587.5618, 656.2725 nm)."""
    focal_shift: LensFocalShift
    spots: list[LensSpot]
    """Per field angle, then per F, d, C line."""
    summary: str
    """The text ``heron lens`` prints."""

def lens(
    prescription: Union[_Path, Sequence[Mapping[str, Any]]],
    fields: _Numbers = (0, 14, 20),
    rays: int = 64,
    reference_wavelength: Optional[float] = None,
) -> LensReport:
    """First order at F, d, C, the chromatic focal shift over 400-700 nm and real-ray
    spot diagrams of a lens prescription, as ``heron lens`` computes them (the numbers
    of its CSV files, exactly).

    prescription: a path to heron's TOML prescription or a pbrt-v4 lens file (``*.dat``),
    or a list of dicts like the TOML's ``[[surface]]`` tables, from the object side:
    radius, thickness, semi_aperture (mm), optionally medium (``"air"`` or any ``ior``
    model) and stop. fields: degrees in (-90, 90). rays: points across the pupil of the
    spot grid (at least 2). reference_wavelength: nm, the focus of the spots and the
    zero of the focal shift (default the prescription's, else the d line).
    """
