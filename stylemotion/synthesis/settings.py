"""Settings of path following (:func:`~stylemotion.synthesis.controller.follow_path`): the ``follow`` config node
of ``stylemotion-generate``, a Hydra structured config (:mod:`stylemotion.cli.schemas`). Kept apart from the
controller so that the command's ``--help`` and a bad key are answered without loading torch.
"""

from __future__ import annotations

from dataclasses import dataclass

from stylemotion.config import ConfigError


@dataclass
class FollowSettings:
    """Settings of :func:`~stylemotion.synthesis.controller.follow_path` (its module doc gives the cost).

    Attributes:
        candidates: ``K``, prior samples per step.
        iterations: Adam steps on the best candidate's ``z`` (0: best of K only).
        lr: Adam learning rate (latent units).
        position_scale_m: ``σ_p``, metres.
        heading_scale_rad: ``σ_θ``, radians.
        prior_weight: ``λ_prior``. At 1 the codes are pulled towards the prior's mode ‖z‖ = 0, far
            inside its typical shell ‖z‖ ≈ √latent_dim, and the stylized models (whose codes vary
            less in step length and turning than the neutral one) miss the path. 0.1 was chosen among
            0.01, 0.03, 0.1, 0.3 and 1 (K and the Adam steps likewise kept) on seeded random
            **validation paths** with Bandai models by suite ``synthesis`` (rule and figures:
            benchmarks/synthesis.md): below it the path barely improves and raw foot skating rises.
        pose_scale_m: ``σ_pose``, metres.
        speed_scale_mps: ``σ_v``, m/s.
        blend_frames: frames over which each transition is blended (:mod:`.stitching`).
        first_foot: planted foot of the first step, ``left`` or ``right``.
        max_steps: safety limit on the number of steps.
    """

    candidates: int = 128
    iterations: int = 40
    lr: float = 0.05
    position_scale_m: float = 0.05
    heading_scale_rad: float = 0.15
    prior_weight: float = 0.1
    pose_scale_m: float = 0.03
    speed_scale_mps: float = 0.1
    blend_frames: int = 6
    first_foot: str = "left"
    max_steps: int = 500

    def __post_init__(self) -> None:
        for name, least in (("candidates", 1), ("iterations", 0), ("max_steps", 1), ("blend_frames", 0)):
            if not getattr(self, name) >= least:
                raise ConfigError(f"follow.{name} must be at least {least}, got {getattr(self, name)}")
        for name in ("position_scale_m", "heading_scale_rad", "pose_scale_m", "speed_scale_mps"):
            if not getattr(self, name) > 0:
                raise ConfigError(f"follow.{name} must be positive, got {getattr(self, name)}")
