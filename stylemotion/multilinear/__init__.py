"""Multilinear motion models (Krüger §4.1): N-mode SVD of class motion tensors, physics-based multiscale time
warping, synthesis of new motions from mode coefficients with the root path, and the tensor-vs-PCA comparison.

Modules: :mod:`.decomposition` (the generic N-mode SVD, shared with :mod:`stylemotion.annotate.tensors`),
:mod:`.physics` (centre-of-mass acceleration and segment angular momenta), :mod:`.warping` (multiscale DTW),
:mod:`.model` (the class tensor and synthesis), :mod:`.compare` (held-out reconstruction, tensor and PCA).
Specification: docs/multilinear.md.
"""
