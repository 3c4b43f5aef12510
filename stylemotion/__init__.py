"""stylemotion: generative models of human motion variation and style from motion capture."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("stylemotion")
except PackageNotFoundError:  # run from a source tree that was never installed
    __version__ = "0+unknown"


def lazy_exports(package: str, where: dict[str, str]):
    """``(__getattr__, __dir__)`` for the init of ``package`` whose exported names load from their submodules on
    first use (PEP 562): ``where`` maps each name to its submodule (``"graph"`` → ``<package>.graph``). A light
    submodule of the package then loads without the heavy ones its init names."""
    import sys
    from importlib import import_module

    def __getattr__(name: str):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(import_module(f"{package}.{where[name]}"), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(where))

    return __getattr__, __dir__
