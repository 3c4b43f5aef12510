"""Foot-contact velocity loss: planted feet of the data stay planted in what a model decodes.

One implementation for every model that decodes motion: the autoencoder
(:class:`~stylemotion.models.autoencoder.MotionAutoencoder`), the per-primitive VAE
(:class:`~stylemotion.models.vae.PrimitiveVAE`) and the models built on it, the style CVAE
(:class:`~stylemotion.models.cvae.StyleCVAE`) and the zero-shot network
(:class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE`). Each adds ``contact_weight · contact`` to its
loss (``contact_weight`` in its Hydra config, 0 by default: off).

As motion diffusion models do (Tevet et al. 2023, "foot contact loss"), the term penalizes the velocity of
the *decoded* feet on the frames where the *real* clip's foot is in ground contact::

    contact = Σ_{i,t,f} c_itf · min_p ‖v_xz(i, t, f, p)‖²  /  Σ_{i,t,f} c_itf            (m²/s²)

* ``c_itf`` is 1 when foot ``f`` (left, right) of real item ``i`` is in contact at frames ``t`` and
  ``t + 1``, by THE detector :func:`stylemotion.primitives.contacts.foot_contacts` (the one the
  foot-skating metric :func:`stylemotion.primitives.skating.foot_skating` uses), run on the real positions;
* ``v_xz(i, t, f, p)`` is the horizontal velocity (m/s, forward difference) of point ``p`` (heel
  ``Foot_*`` or ball ``Toes_*``) of the decoded motion's foot ``f``, in global positions recovered from
  the decoded 66-dim frames by the differentiable inverse representation
  (:func:`stylemotion.representation.frames_to_positions`: root velocity and yaw rate integrated), so
  a foot that slides because the root moves under it is penalized too;
* the slower of heel and ball is the planted point, as in
  :func:`stylemotion.primitives.contacts.planted_point_speed` (the foot pivots about its heel at strike
  and its ball at push-off): the term is the skating metric's speed, squared and made differentiable.

The feature models (VAE, CVAE, zero-shot) decode their reconstructions through the frozen autoencoder
(its gradient reaches their decoders, not its weights) on the primitive's canonical timeline, whose frame
rate is each clip's playback rate ``(L − 1) / duration`` (:func:`stylemotion.primitives.segmentation.playback_fps`);
the real clip's contacts, detected on its recorded frames, are carried to that timeline by
:func:`timeline_contacts`.

Generated motion has no real clip. For the style CVAE's draws (``sample_contact_weight``) the contacts are
those the detector finds on the *decoded* motion itself (:func:`own_contacts`, not differentiated): the term
then asks the feet the motion plants to stay still, wherever it plants them, so it does not pull the
draws' step timing towards the neutral content clips (as the term on the content clips' reconstructions does).
A draw that never plants has no own contact; ``sample_contacts=content`` holds every draw on the primitive's
contact template instead (the content clips' majority contacts, :func:`contact_runs` of it) and adds
:func:`midstance_loss`, which holds heel and ball both in the middle of each contact run.
"""

from __future__ import annotations

import numpy as np
import torch

from stylemotion.primitives.contacts import foot_contacts
from stylemotion.representation import frames_to_positions
from stylemotion.skeleton import FOOT_POINTS

__all__ = ["contact_runs", "contact_velocity_loss", "midstance_loss", "own_contacts", "planted_speed_squared",
           "timeline_contacts", "window_contacts"]


def planted_speed_squared(frames: torch.Tensor, fps: float | torch.Tensor) -> torch.Tensor:
    """Squared horizontal speed of each foot's planted (slower) point between consecutive frames.

    Args:
        frames: ``(n, T, 66)`` raw frames (torch, differentiable), ``T ≥ 2``.
        fps: frames per second of ``frames``: a number, or ``(n,)`` one rate per motion (e.g. the
            playback rate of a time-normalized clip).

    Returns:
        ``(n, T − 1, 2)`` m²/s², feet ``[left, right]``: ``min`` over heel and ball of ``‖Δx_xz · fps‖²``
        of the global positions (:func:`~stylemotion.representation.frames_to_positions`, from the origin).
    """
    if frames.dim() != 3 or frames.shape[-2] < 2:
        raise ValueError(f"frames must be (n, T ≥ 2, 66), got {tuple(frames.shape)}")
    rate = torch.as_tensor(fps, dtype=frames.dtype, device=frames.device)
    rate = rate.reshape(-1, 1) if rate.dim() else rate  # (n, 1): broadcast against the time axis
    positions = frames_to_positions(frames, rate)  # (n, T, 21, 3)
    points = positions[..., torch.as_tensor(FOOT_POINTS.reshape(-1), device=frames.device), :][..., [0, 2]]
    step = points[:, 1:] - points[:, :-1]  # (n, T − 1, 4, 2) metres per frame
    per_second = rate.reshape(-1, 1, 1) if rate.dim() else rate
    squared = step.square().sum(-1) * per_second.square()  # (n, T − 1, 4)
    return squared.unflatten(-1, (2, 2)).amin(-1)


def contact_velocity_loss(frames: torch.Tensor, contacts: torch.Tensor, fps: float | torch.Tensor) -> torch.Tensor:
    """Mean squared planted-foot speed of decoded ``frames`` over the real clips' contact foot-frames.

    Args:
        frames: ``(n, T, 66)`` decoded raw frames (differentiable).
        contacts: ``(n, T, 2)`` bool contacts of the *real* motions on the same frames (see the module doc);
            a step ``t → t + 1`` counts where both ends are in contact.
        fps: frames per second, a number or ``(n,)``.

    Returns:
        Scalar, m²/s² (0 when no foot-frame is in contact).
    """
    if contacts.shape != frames.shape[:-1] + (2,):
        raise ValueError(f"contacts must be (n, T, 2) for frames {tuple(frames.shape)}, got {tuple(contacts.shape)}")
    mask = (contacts[:, 1:] & contacts[:, :-1]).to(frames.dtype)
    squared = planted_speed_squared(frames, fps)
    return (squared * mask).sum() / mask.sum().clamp_min(1.0)


def contact_runs(contacts: torch.Tensor) -> list[tuple[int, int, int]]:
    """The contact runs of one contact pattern ``(T, 2)`` bool: ``(foot, first, last)`` frames of each maximal run
    of at least 2 frames (a single frame has no step)."""
    runs = []
    flags = contacts.detach().cpu().bool().numpy()
    for foot in range(flags.shape[1]):
        edges = np.diff(np.concatenate([[0], flags[:, foot].astype(np.int8), [0]]))
        runs += [(foot, int(a), int(b) - 1) for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1))
                 if b - a >= 2]
    return runs


def midstance_loss(frames: torch.Tensor, runs: list[tuple[int, int, int]], fps: float | torch.Tensor
                   ) -> torch.Tensor:
    """Mean squared horizontal speed of heel **and** ball over the middle half of each contact run (m²/s²).

    In the middle of a stance the whole foot is flat on the ground, so neither point moves; at its ends the foot
    rolls about one point while the other moves (why :func:`contact_velocity_loss` takes the slower point per
    frame). The per-frame slower point can be cheated: heel and ball that take turns to stay still let the foot
    walk backwards under a moving root at no cost. Here both points are held over frames ``a + ⌊(b − a)/4⌋`` to
    ``b − ⌊(b − a)/4⌋`` of each run ``(foot, a, b)`` (the same frames for every motion, e.g. a primitive's contact
    template), steps between consecutive frames.

    Args:
        frames: ``(n, T, 66)`` decoded raw frames (differentiable).
        runs: contact runs on those frames (:func:`contact_runs`).
        fps: frames per second, a number or ``(n,)``.

    Returns:
        Scalar (0 without runs).
    """
    if not runs:
        return frames.new_zeros(())
    rate = torch.as_tensor(fps, dtype=frames.dtype, device=frames.device)
    rate = rate.reshape(-1, 1) if rate.dim() else rate
    positions = frames_to_positions(frames, rate)  # (n, T, 21, 3)
    points = torch.as_tensor(FOOT_POINTS, device=frames.device)  # (2 feet, 2 points)
    per_second = rate.reshape(-1, 1, 1) if rate.dim() else rate
    parts = []
    for foot, a, b in runs:
        quarter = (b - a) // 4
        mid = positions[:, a + quarter:b - quarter + 1][:, :, points[foot]][..., [0, 2]]  # (n, m, 2 points, 2)
        parts.append((mid[:, 1:] - mid[:, :-1]).square().sum(-1).mul(per_second.square()).flatten(1))
    return torch.cat(parts, dim=1).mean()


def window_contacts(frames: torch.Tensor, fps: float) -> torch.Tensor:
    """Contacts of real frame windows (the autoencoder's batches) by
    :func:`~stylemotion.primitives.contacts.foot_contacts`.

    Args:
        frames: ``(n, T, 66)`` raw frames at ``fps``, ``T ≥ 2``.
        fps: frames per second.

    Returns:
        ``(n, T, 2)`` bool on ``frames``' device (resting heights estimated per window).
    """
    positions = frames_to_positions(frames.detach().double().cpu().numpy(), fps)
    return torch.from_numpy(foot_contacts(positions, fps)).to(frames.device)


def timeline_contacts(positions: torch.Tensor, num_frames: torch.Tensor, fps: float, length: int) -> torch.Tensor:
    """Contacts of recorded clips carried to their canonical timeline of ``length`` frames.

    Contacts are detected on each clip as recorded (:func:`~stylemotion.primitives.contacts.foot_contacts`,
    resting heights of the clip), then timeline frame ``j`` takes the contact of the recorded frame nearest
    to the same normalized time ``j / (length − 1)`` (as :func:`stylemotion.primitives.segmentation.time_normalize`
    maps times).

    Args:
        positions: ``(n, frames, 21, 3)`` padded recorded positions, metres (e.g. a
            :class:`~stylemotion.datamodules.features.FeatureDataModule` batch's ``positions``).
        num_frames: ``(n,)`` valid frames of each clip (≥ 2).
        fps: frame rate of ``positions``.
        length: canonical timeline frames ``L`` (≥ 2).

    Returns:
        ``(n, length, 2)`` bool on ``positions``' device.
    """
    p = positions.detach().cpu().numpy()
    counts = num_frames.detach().cpu().numpy().astype(np.int64).reshape(-1)
    out = np.zeros((len(p), length, 2), dtype=bool)
    grid = np.linspace(0.0, 1.0, length)
    for count in np.unique(counts):  # clips of one length are detected together
        rows = np.flatnonzero(counts == count)
        contact = foot_contacts(p[rows, :count], fps)  # (k, count, 2)
        out[rows] = contact[:, np.rint(grid * (count - 1)).astype(np.int64)]
    return torch.from_numpy(out).to(positions.device)


def own_contacts(frames: torch.Tensor, fps: torch.Tensor) -> torch.Tensor:
    """Contacts of decoded (generated) motions detected on themselves by
    :func:`~stylemotion.primitives.contacts.foot_contacts` (resting heights estimated per motion).

    Args:
        frames: ``(n, T, 66)`` raw frames, ``T ≥ 2`` (not differentiated).
        fps: ``(n,)`` frames per second of each motion (e.g. its playback rate).

    Returns:
        ``(n, T, 2)`` bool on ``frames``' device.
    """
    rate = fps.detach().double().cpu().reshape(-1)
    if len(rate) != frames.shape[0]:
        raise ValueError(f"fps must hold one rate per motion ({frames.shape[0]}), got {len(rate)}")
    positions = frames_to_positions(frames.detach().double().cpu(), rate[:, None]).numpy()
    out = np.zeros(frames.shape[:-1] + (2,), dtype=bool)
    for i, (motion, motion_fps) in enumerate(zip(positions, rate.tolist())):  # the speed thresholds are per second
        out[i] = foot_contacts(motion, motion_fps)
    return torch.from_numpy(out).to(frames.device)
