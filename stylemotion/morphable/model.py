"""A motion primitive of the Morphable Graph (Du §3.3, §4.4.1): spline functions, time warping, (S)FPCA
latent space and a Gaussian mixture; sampling into :class:`~stylemotion.models.sampling.MotionSamples`.

Fitting (:func:`fit_primitive`), for the clips of one primitive:

1. channels of each clip (:mod:`.channels`: quaternions fitted with the project's IK, or 66-dim frames);
2. DTW of each clip to the median-length clip (:mod:`.warping`): aligned channels on the canonical
   timeline of ``L`` frames and a warping function ``w`` (frames);
3. cubic B-spline coefficients (:mod:`.bspline`) of the aligned channels and of ``w``, with ``K`` per
   channel (given, or the smallest ``K`` whose joint-space RMSE is under a cut-off, Fig. 3.9);
4. FPCA / normalized FPCA / SFPCA of the coefficient vectors (:mod:`.fpca`) to ``d`` dimensions;
5. a BIC-chosen Gaussian mixture of the latent codes (:mod:`.gmm`).

Decoding a code ``s``: coefficients → ``w`` (made monotone; its end ``w(L−1)`` is the clip's length in
frames at the data's fps) → the spatial splines evaluated at the canonical times of the clip's own
frames → joint positions → 66-dim frames. Models are saved as one ``.npz`` of plain arrays and a JSON
string (:meth:`MorphableModel.save`), loaded with ``allow_pickle=False``.
"""

from __future__ import annotations

import io
import json
import logging
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch

from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.models.sampling import MotionSamples, pad_motions
from stylemotion.morphable.bspline import SplineBasis
from stylemotion.morphable.channels import Channels
from stylemotion.morphable.fpca import FunctionalPCA, fit_reduction
from stylemotion.morphable.gmm import LatentGMM, fit_gmm
from stylemotion.morphable.tree import TREE_SAMPLES, SpaceTree
from stylemotion.morphable.warping import canonical_times, dtw_warp, monotone, resample
from stylemotion.primitives.segmentation import Clip, canonical_timelines, time_normalize
from stylemotion.representation import JOINT_DIMS, positions_to_frames

log = logging.getLogger(__name__)
#: What a tree's splits may cluster (:meth:`MorphableModel.build_tree`).
TREE_SPACES = ("keyframes", "latent")

FORMAT = "stylemotion.morphable/v1"
#: Default joint-space RMSE cut-off (metres) for choosing K (Fig. 3.9).
RMSE_CUTOFF_M = 0.01


@dataclass
class FitSettings:
    """Settings of :func:`fit_primitive`.

    Attributes:
        representation: ``quaternion`` (the thesis') or ``frames``.
        num_coefficients: ``K`` per channel, or None for the smallest ``K`` in ``4 … L`` whose joint-space
            RMSE of the spline fit is ≤ ``rmse_cutoff_m``.
        rmse_cutoff_m: metres.
        latent_dim: ``d``.
        reduction: ``fpca``, ``normalized`` or ``sfpca``.
        sfpca_iterations: L-BFGS-B iterations.
        max_components: largest mixture tried by BIC.
        seed: seeds the mixture's EM.
    """

    representation: str = "quaternion"
    num_coefficients: int | None = None
    rmse_cutoff_m: float = RMSE_CUTOFF_M
    latent_dim: int = 20
    reduction: str = "sfpca"
    sfpca_iterations: int = 30
    max_components: int = 10
    seed: int = 0


@dataclass
class FunctionalData:
    """Clips of one primitive as aligned channels and warping functions (steps 1–2).

    Attributes:
        channels: the representation.
        aligned: ``(n, L, C)`` channels on the canonical timeline.
        warps: ``(n, L)`` warping functions, frames at ``fps``.
        fps: the clips' frame rate.
        reference: index of the median-length clip the others are aligned to.
    """

    channels: Channels
    aligned: np.ndarray
    warps: np.ndarray
    fps: float
    reference: int

    @property
    def length(self) -> int:
        return int(self.aligned.shape[1])

    @property
    def playback_fps(self) -> np.ndarray:
        """``(n,)`` rate at which the canonical timeline lasts each clip's duration."""
        return (self.length - 1) * self.fps / self.warps[:, -1]

    def joint_positions(self, aligned: np.ndarray) -> np.ndarray:
        """``(n, L, 21, 3)`` positions of ``(n, L, C)`` aligned channels of these clips."""
        return self.channels.positions(aligned, self.playback_fps)


def functional_data(clips: Sequence[Clip], representation: str = "quaternion") -> FunctionalData:
    """Channels of ``clips`` (one primitive) aligned by DTW to the median-length clip."""
    if len(clips) < 2:
        raise ValueError(f"a primitive model needs at least 2 clips, got {len(clips)}")
    fps = {c.fps for c in clips}
    if len(fps) != 1:
        raise ValueError(f"clips have different frame rates {sorted(fps)}; resample them to one first")
    timelines = canonical_timelines(clips)
    if len(timelines) != 1:
        raise ValueError(f"clips of one primitive expected, got {sorted(timelines)}")
    length = next(iter(timelines.values()))
    reference = int(np.argmin([abs(c.num_frames - length) for c in clips]))
    length = clips[reference].num_frames
    channels = Channels.for_positions(representation, [c.positions for c in clips])
    ref_features = clips[reference].frames[:, JOINT_DIMS]
    aligned, warps = [], []
    for clip in clips:
        warp = dtw_warp(ref_features, clip.frames[:, JOINT_DIMS])
        aligned.append(resample(channels.encode(clip.positions, clip.frames), warp))
        warps.append(warp)
    return FunctionalData(channels, np.stack(aligned), np.stack(warps), float(fps.pop()), reference)


def spline_rmse(data: FunctionalData, num_coefficients: int) -> float:
    """Joint-space RMSE (metres, over clips, frames and joints) of the ``K``-coefficient spline fit of the
    aligned channels."""
    basis = SplineBasis(num_coefficients)
    fitted = basis.evaluate(basis.fit(data.aligned), data.length)
    diff = data.joint_positions(fitted) - data.joint_positions(data.aligned)
    return float(np.sqrt((diff ** 2).sum(-1).mean()))


def choose_coefficients(data: FunctionalData, cutoff_m: float) -> tuple[int, dict[int, float]]:
    """Smallest ``K`` in ``4 … L`` with :func:`spline_rmse` ≤ ``cutoff_m`` (else ``L``), and the RMSEs tried."""
    tried: dict[int, float] = {}
    for k in range(4, data.length + 1):
        tried[k] = spline_rmse(data, k)
        if tried[k] <= cutoff_m:
            return k, tried
    return data.length, tried


@dataclass
class MorphableModel:
    """One motion primitive's statistical model (see the module doc).

    Attributes:
        channels: the representation (with its bone offsets).
        basis: the spline basis (``K`` coefficients per channel).
        reduction: the (scaled) PCA of coefficient vectors ``(C + 1) · K`` long.
        gmm: the latent mixture.
        length: ``L``, frames of the canonical timeline.
        fps: frames per second of decoded motions.
        meta: plain values (primitive, action, style, settings, fit record).
        tree: the space-partitioning tree over samples of the mixture (:mod:`.tree`), if built.

    The tree's keyframe boxes (:mod:`.bounds`) are computed when first needed and kept in memory only.
    """

    channels: Channels
    basis: SplineBasis
    reduction: FunctionalPCA
    gmm: LatentGMM
    length: int
    fps: float
    meta: dict[str, Any] = field(default_factory=dict)
    tree: SpaceTree | None = None
    _bounds: Any = field(default=None, init=False, repr=False, compare=False)

    # -- interfaces shared with the VAEs (MotionGraph, evaluation)

    @property
    def latent_dim(self) -> int:
        return self.reduction.latent_dim

    @property
    def timeline_frames(self) -> int:
        return self.length

    def eval(self) -> MorphableModel:
        return self

    def requires_grad_(self, flag: bool = True) -> MorphableModel:
        return self

    # -- decoding

    def coefficients(self, latent: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Spatial coefficients ``(n, C, K)`` and warping coefficients ``(n, K)`` of ``(n, d)`` codes."""
        vec = self.reduction.reconstruct(np.atleast_2d(latent)).reshape(-1, self.channels.size + 1,
                                                                          self.basis.num_coefficients)
        return vec[:, :-1], vec[:, -1]

    def warps(self, warp_coefficients: np.ndarray) -> np.ndarray:
        """``(n, L)`` monotone warping functions (frames), each lasting at least one frame."""
        w = monotone(self.basis.evaluate(warp_coefficients[:, None, :], self.length)[..., 0])
        return monotone(w, last=np.maximum(w[:, -1], 1.0))

    def canonical_positions(self, latent: np.ndarray, rotations: bool = False):
        """``(n, L, 21, 3)`` positions on the canonical timeline (and global rotations with ``rotations``)."""
        spatial, warp = self.coefficients(latent)
        channels = self.basis.evaluate(spatial, self.length)
        rate = (self.length - 1) * self.fps / self.warps(warp)[:, -1]
        return self.channels.positions(channels, rate, rotations=rotations)

    def poses_at(self, latent: np.ndarray, frames: Sequence[int], rotations: bool = False):
        """``(n, len(frames), 21, 3)`` positions at canonical ``frames`` only (and global rotations with
        ``rotations``): for the quaternion representation just those frames are evaluated (what constraint
        searches over thousands of codes need); the ``frames`` representation integrates the whole clip."""
        frames = list(frames)
        if self.channels.kind != "quaternion":
            out = self.canonical_positions(latent, rotations=rotations)
            return (out[0][:, frames], out[1][:, frames]) if rotations else out[:, frames]
        spatial, _ = self.coefficients(latent)
        times = np.asarray(frames, dtype=np.float64) / (self.length - 1)
        return self.channels.positions(self.basis.evaluate(spatial, times), rotations=rotations)

    def decode_latent(self, latent: np.ndarray | torch.Tensor) -> MotionSamples:
        """Motions of ``(n, d)`` codes, at :attr:`fps` with their own durations (see the module doc)."""
        latent = np.atleast_2d(latent.detach().cpu().numpy() if isinstance(latent, torch.Tensor) else latent)
        spatial, warp_coeffs = self.coefficients(latent)
        warps = self.warps(warp_coeffs)
        counts = np.maximum(np.round(warps[:, -1]).astype(int) + 1, 2)
        channel_seqs = [self.basis.evaluate(spatial[i], canonical_times(warps[i], counts[i]))
                        for i in range(len(latent))]
        padded, num_frames = pad_motions([c.astype(np.float64) for c in channel_seqs])
        if self.channels.kind == "quaternion":
            positions = self.channels.positions(padded.numpy().astype(np.float64))
            frames = [positions_to_frames(positions[i, :counts[i]], self.fps)[0] for i in range(len(latent))]
        else:
            frames = [seq.astype(np.float32) for seq in channel_seqs]
            positions = np.stack([self.channels.positions(padded[i].numpy().astype(np.float64), self.fps)
                                  for i in range(len(latent))]) if len(latent) else np.zeros((0, 2, 21, 3))
        frames_t, _ = pad_motions(frames)
        pos_t, _ = pad_motions([positions[i, :counts[i]] for i in range(len(latent))])
        normalized = np.stack([time_normalize(f, self.length) for f in frames])
        features = np.concatenate([spatial, warp_coeffs[:, None]], axis=1).astype(np.float32)
        duration = torch.from_numpy(((counts - 1) / self.fps).astype(np.float32))
        return MotionSamples(pos_t, frames_t, num_frames, duration, torch.from_numpy(features),
                             torch.from_numpy(normalized), float(self.fps),
                             torch.from_numpy(latent.astype(np.float32)))

    @property
    def primitive_name(self) -> str | None:
        """``<action>_<primitive>`` (e.g. ``walk_leftStance``) as the other models name it; None if not recorded."""
        primitive, action = self.meta.get("primitive"), self.meta.get("action")
        if primitive and action and not str(primitive).startswith(f"{action}_"):
            return f"{action}_{primitive}"
        return None if primitive is None else str(primitive)

    @property
    def style_name(self) -> str:
        """The style of the clips it was fitted on; ``all`` for several styles (or none recorded)."""
        style = self.meta.get("style")
        return "all" if style in (None, "all") else str(style)

    @torch.no_grad()
    def sample(self, n: int, seed: int = 0, chunk: int = 2000) -> MotionSamples:
        """``n`` motions drawn from the mixture (seeded: the same seed gives the same motions)."""
        latent = self.gmm.sample(n, seed)
        parts = [self.decode_latent(latent[i:i + chunk]) for i in range(0, n, chunk)]
        return parts[0] if len(parts) == 1 else concat_samples(parts)

    # -- files

    def to_arrays(self) -> dict[str, np.ndarray]:
        meta = {**self.meta, "format": FORMAT, "representation": self.channels.kind, "length": self.length,
                "fps": self.fps, "num_coefficients": self.basis.num_coefficients}
        arrays = {"meta_json": np.array(json.dumps(meta, default=float)), "pca_mean": self.reduction.mean,
                  "pca_components": self.reduction.components, "pca_scale": self.reduction.scale,
                  "pca_variance": self.reduction.variance, **self.gmm.to_arrays()}
        if self.channels.offsets is not None:
            arrays["offsets"] = self.channels.offsets
        if self.tree is not None:
            arrays.update(self.tree.to_arrays())
        return arrays

    def build_tree(self, samples: int = TREE_SAMPLES, split: str = "kmeans", seed: int = 0, space: str = "keyframes",
                   leaf_size: int = 4, **kwargs) -> SpaceTree:
        """Build (and keep) the space-partitioning tree over ``samples`` codes drawn from the mixture, split
        by clustering the codes (``space="latent"``, the thesis') or their keyframe positions and rotations
        (``"keyframes"``, :func:`.bounds.clustering_features`)."""
        from stylemotion.morphable.bounds import clustering_features

        if space not in TREE_SPACES:
            raise ValueError(f"unknown tree space {space!r}; one of {list(TREE_SPACES)}")
        codes = self.gmm.sample(samples, seed)
        features = clustering_features(self, codes) if space == "keyframes" else None
        self.tree = SpaceTree.build(codes, split=split, seed=seed, leaf_size=leaf_size, features=features,
                                    space=space, **kwargs)
        return self.tree

    def ensure_tree(self) -> SpaceTree:
        """The tree, built with the defaults (and not saved) if the model has none."""
        if self.tree is None:
            log.info("building the space-partitioning tree of %s (not saved with the model)",
                     self.meta.get("primitive"))
            self.build_tree()
        return self.tree

    def keyframe_bounds(self):
        """The tree's :class:`~.bounds.KeyframeBounds` (computed on first use, ~1 s for 10,000 codes)."""
        from stylemotion.morphable.bounds import KeyframeBounds

        tree = self.ensure_tree()
        if self._bounds is None or self._bounds[0] is not tree:  # kept with the tree it was computed for
            self._bounds = (tree, KeyframeBounds.of(self, tree))
        return self._bounds[1]

    def save(self, path: str | Path) -> Path:
        """Write the model to ``path`` (``.npz``) atomically; returns the path."""
        path = Path(path).expanduser()
        if path.suffix != ".npz":
            raise ValueError(f"a morphable model file ends in .npz, got {path}")
        buffer = io.BytesIO()
        np.savez(buffer, **self.to_arrays())
        atomic_write_bytes(path, buffer.getvalue())
        return path

    @classmethod
    def load(cls, path: str | Path) -> MorphableModel:
        """A model saved by :meth:`save` (a file, or a run folder holding ``model.npz``). ``stylemotion.load(path)``
        reads it through here, with the sampling interface and ``describe()`` of every other model."""
        path = Path(path).expanduser()
        if path.is_dir():
            path = path / "model.npz"
        if not path.is_file():
            raise FileNotFoundError(f"no morphable model at {path}")
        with np.load(path, allow_pickle=False) as z:
            if "meta_json" not in z.files:
                raise ValueError(f"{path} is not a morphable model (no meta_json array)")
            meta = json.loads(str(z["meta_json"]))
            if meta.get("format") != FORMAT:
                raise ValueError(f"{path}: unknown model format {meta.get('format')!r}, expected {FORMAT!r}")
            channels = Channels(meta["representation"], z["offsets"] if "offsets" in z.files else None)
            reduction = FunctionalPCA(z["pca_mean"], z["pca_components"], z["pca_scale"], z["pca_variance"])
            gmm = LatentGMM.from_arrays(z)
            tree = SpaceTree.from_arrays(z) if "tree_latent" in z.files else None
        meta["path"] = str(path)
        return cls(channels, SplineBasis(int(meta["num_coefficients"])), reduction, gmm, int(meta["length"]),
                   float(meta["fps"]), meta, tree)


def concat_samples(parts: Sequence[MotionSamples]) -> MotionSamples:
    """One :class:`MotionSamples` of several (padded to the longest)."""
    width = max(p.positions.shape[1] for p in parts)

    def pad(t: torch.Tensor) -> torch.Tensor:
        extra = width - t.shape[1]
        return t if extra == 0 else torch.cat([t, t[:, -1:].expand(-1, extra, *t.shape[2:])], dim=1)

    return MotionSamples(torch.cat([pad(p.positions) for p in parts]), torch.cat([pad(p.frames) for p in parts]),
                         torch.cat([p.num_frames for p in parts]), torch.cat([p.duration_s for p in parts]),
                         torch.cat([p.features for p in parts]), torch.cat([p.normalized_frames for p in parts]),
                         parts[0].fps, torch.cat([p.latent for p in parts]))


def coefficient_vectors(data: FunctionalData, basis: SplineBasis) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """``(n, (C + 1) K)`` coefficient vectors (spatial channels, then the warp), each coefficient's function
    index ``(D,)``, and the function names."""
    spatial = basis.fit(data.aligned)
    warp = basis.fit(data.warps[:, :, None])
    vectors = np.concatenate([spatial, warp], axis=1).reshape(len(spatial), -1)
    groups = np.empty(data.channels.size + 1, dtype=np.int64)
    names = []
    for g, (name, sl) in enumerate(data.channels.functions):
        groups[sl] = g
        names.append(name)
    groups[-1] = len(names)
    names.append("time_warping")
    return vectors, np.repeat(groups, basis.num_coefficients), names


def joint_error_function(data: FunctionalData, basis: SplineBasis, vectors: np.ndarray):
    """Eq. 3.8's error: reconstructed vectors ``(n, D)`` → mean squared joint distance (m²) to the FK of
    the clips' own functional data ``vectors``."""
    size = data.channels.size + 1

    def positions(vecs: np.ndarray) -> np.ndarray:
        spatial = vecs.reshape(len(vecs), size, basis.num_coefficients)[:, :-1]
        return data.joint_positions(basis.evaluate(spatial, data.length))

    target = positions(vectors)

    def error(reconstructed: np.ndarray) -> float:
        return float(((positions(reconstructed) - target) ** 2).sum(-1).mean())

    return error


def fit_primitive(clips: Sequence[Clip], settings: FitSettings | None = None, meta: dict[str, Any] | None = None,
                  validation: Sequence[Clip] | None = None) -> MorphableModel:
    """Fit a :class:`MorphableModel` to the clips of one primitive (see the module doc). With ``validation``
    clips (never the reported ones), SFPCA keeps whichever of its start and its optimized weights reconstructs
    them better (:func:`~stylemotion.morphable.fpca.fit_reduction`'s ``selection_error``)."""
    settings = settings or FitSettings()
    if len(clips) <= settings.latent_dim:
        raise ValueError(f"{len(clips)} clips cannot give {settings.latent_dim} latent dimensions (PCA of n clips has "
                         f"at most n − 1); lower latent_dim below {len(clips)} or add clips")
    data = functional_data(clips, settings.representation)
    if settings.num_coefficients is None:
        k, tried = choose_coefficients(data, settings.rmse_cutoff_m)
    else:
        k, tried = int(settings.num_coefficients), {}
        if k > data.length:
            raise ValueError(f"num_coefficients={k} exceeds the canonical timeline's {data.length} frames")
    basis = SplineBasis(k)
    vectors, groups, names = coefficient_vectors(data, basis)
    error = joint_error_function(data, basis, vectors)
    select = None
    if validation and settings.reduction == "sfpca":
        from stylemotion.morphable.heldout_vectors import encode_heldout, heldout_error_function

        held = encode_heldout(data, clips[data.reference], basis, validation)
        val_error = heldout_error_function(data, basis, held)

        def select(rebuild) -> float:
            return val_error(rebuild(held.vectors))
    reduction, record = fit_reduction(vectors, groups, settings.latent_dim, settings.reduction, error,
                                      settings.sfpca_iterations, selection_error=select)
    latent = reduction.project(vectors)
    gmm = fit_gmm(latent, settings.max_components, settings.seed)
    first = clips[0]
    fit_record = {"clips": len(clips), "spline_rmse_m": {str(a): b for a, b in tried.items()},
                  "joint_rmse_m": float(np.sqrt(error(reduction.reconstruct(latent)))),
                  "reduction": record, "functions": names,
                  "function_weights": [float(reduction.scale[groups == g][0]) for g in range(len(names))],
                  "gmm_components": gmm.num_components}
    styles = {c.style for c in clips}
    meta = {"action": first.action, "primitive": first.primitive, "style": first.style if len(styles) == 1 else "all",
            "settings": {k_: v for k_, v in vars(settings).items()}, "fit": fit_record, **(meta or {})}
    log.info("%s_%s: %d clips, L=%d, K=%d, d=%d, %d GMM component(s), joint RMSE %.4f m", first.action,
             first.primitive, len(clips), data.length, k, settings.latent_dim, gmm.num_components,
             fit_record["joint_rmse_m"])
    return MorphableModel(data.channels, basis, reduction, gmm, data.length, data.fps, meta)


def refit_mixture(model: MorphableModel, clips: Sequence[Clip], seed: int) -> MorphableModel:
    """``model`` with its mixture refitted (EM seeded by ``seed``) on the codes of its training ``clips``; the
    functional data and the reduction are deterministic, so this is what another fitting seed changes. No tree."""
    settings = FitSettings(**model.meta["settings"])
    data = functional_data(clips, settings.representation)
    if data.length != model.length:
        raise ValueError(f"clips give a {data.length}-frame timeline, the model has {model.length}: not its clips")
    vectors, _, _ = coefficient_vectors(data, model.basis)
    gmm = fit_gmm(model.reduction.project(vectors), settings.max_components, int(seed))
    meta = json.loads(json.dumps(model.meta))
    meta["settings"]["seed"] = int(seed)
    meta["fit"]["gmm_components"] = gmm.num_components
    return MorphableModel(model.channels, model.basis, model.reduction, gmm, model.length, model.fps, meta)


def reconstruction_error(model: MorphableModel, clips: Sequence[Clip]) -> float:
    """Joint-space RMSE (metres) of clips (e.g. held out) projected into the model's latent space and back,
    on the canonical timeline. Each clip is aligned by DTW to the model's mean motion (code 0 … the mixture's
    mean), then fitted, projected and reconstructed; the error compares FK of its own spline fit with FK of
    the reconstruction."""
    if not clips:
        raise ValueError("no clip to reconstruct")
    mean_code = (model.gmm.weights[:, None] * model.gmm.means).sum(0)
    reference = model.decode_latent(mean_code[None]).normalized_frames[0].numpy()[:, JOINT_DIMS]
    vectors, rates = [], []
    for clip in clips:
        warp = dtw_warp(reference, clip.frames[:, JOINT_DIMS])
        aligned = resample(model.channels.encode(clip.positions, clip.frames), warp)
        coeffs = np.concatenate([model.basis.fit(aligned), model.basis.fit(warp[:, None])], axis=0)
        vectors.append(coeffs.ravel())
        rates.append((model.length - 1) * model.fps / warp[-1])
    vectors = np.stack(vectors)
    shape = (len(vectors), model.channels.size + 1, model.basis.num_coefficients)
    rebuilt = model.reduction.reconstruct(model.reduction.project(vectors))
    rates = np.asarray(rates)
    own = model.channels.positions(model.basis.evaluate(vectors.reshape(shape)[:, :-1], model.length), rates)
    back = model.channels.positions(model.basis.evaluate(rebuilt.reshape(shape)[:, :-1], model.length), rates)
    return float(np.sqrt(((own - back) ** 2).sum(-1).mean()))
