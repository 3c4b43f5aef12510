"""stylemotion: generative models of human motion variation and style from motion capture.

The calls a notebook uses (each loads its part of the package on first use, so ``import stylemotion`` is quick)::

    import stylemotion

    run = stylemotion.load("runs/reproduce/synthetic")     # any model: .ckpt, model.npz, a run or style folder
    print(run.describe())                                   # kind, styles, data, the command that trained it, commit
    walks = run.sample(8, seed=0, style="elderly")          # MotionSamples: positions (8, frames, 21, 3) metres
    stylemotion.view(walks)                                 # the three.js viewer, inline and offline

    stylemotion.evaluate("runs/reproduce/synthetic", "runs/eval/mine", samples=200)    # Tables 5.1-5.3, metrics
    stylemotion.walk("runs/reproduce/synthetic", "runs/generate/mine", style="elderly", path=[(0, 0), (0, 5)])
    stylemotion.search_motion("synthetic_walk_elderly_000:30-90", "runs/search/mine", top=5)
    stylemotion.reconstruct_motion("synthetic_walk_normal_000:0-120", "runs/reconstruct/mine")
    stylemotion.learn_templates("runs/annotate/templates")
    stylemotion.annotate_motion("capture.bvh", "runs/annotate/templates", "runs/annotate/mine")

Each writes the output folder of its command (``stylemotion-eval``, ``-generate``, ``-search``, ``-reconstruct``,
``-annotate``) with the command's defaults; ``help(stylemotion.<call>)`` says what it takes. The notebooks in
``notebooks/`` walk through one task each.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("stylemotion")
except PackageNotFoundError:  # run from a source tree that was never installed
    __version__ = "0+unknown"


def lazy_exports(package: str, where: dict[str, str]):
    """``(__getattr__, __dir__)`` for the init of ``package`` whose exported names load from their submodules on
    first use (PEP 562): ``where`` maps each name to its submodule (``"graph"`` → ``<package>.graph``) or, for a
    name re-exported from elsewhere, to a full module name (``"stylemotion.models.loading"``). A light submodule of
    the package then loads without the heavy ones its init names."""
    import sys
    from importlib import import_module

    def __getattr__(name: str):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module = where[name] if where[name].startswith("stylemotion.") else f"{package}.{where[name]}"
        value = getattr(import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(where))

    return __getattr__, __dir__


#: The public API (see the module doc): name → the module that defines it, loaded on first use.
_API = {
    "load": "loading", "sample": "loading", "Description": "loading", "LoadError": "loading",
    "evaluate": "api", "walk": "api", "search_motion": "api", "reconstruct_motion": "api",
    "learn_templates": "api", "annotate_motion": "api", "data_config": "api",
    "view": "viewer.notebook",
}

__all__ = ["Description", "LoadError", "annotate_motion", "data_config", "evaluate", "learn_templates", "load",
           "reconstruct_motion", "sample", "search_motion", "view", "walk"]

__getattr__, __dir__ = lazy_exports(__name__, _API)
