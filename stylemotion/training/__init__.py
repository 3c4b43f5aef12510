"""Training: fit one model (:mod:`.fit`, ``stylemotion-train``), the reproduction pipeline
(:mod:`.reproduction`, ``stylemotion-reproduce``) and what later tools read of a finished run folder
(:mod:`.run_folder`).

``stylemotion.training.run`` (a notebook's entry point) and ``stylemotion.training.CheckpointAtTrainEnd``
(the ``_target_`` of configs saved by earlier runs) are kept here as names of :mod:`.fit`.
"""

from stylemotion.training.fit import CheckpointAtTrainEnd, run

__all__ = ["CheckpointAtTrainEnd", "run"]
