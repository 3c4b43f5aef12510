"""Console scripts: thin entry points on one skeleton (:mod:`stylemotion.cli.skeleton`).

Each module here names its command's library function (imported when the command runs, so ``--help``
and a bad argument answer without loading models or data) and hands it to
:func:`~stylemotion.cli.skeleton.hydra_command` or :func:`~stylemotion.cli.skeleton.argparse_command`.
The work lives in the library, so notebooks can call it. Every command explains itself (``--help``:
Hydra help configs in ``stylemotion/configs/hydra/help/``), reports what it did through :mod:`logging`,
and ends bad input in one line ``stylemotion-<command>: <message naming the key or file>`` with exit
status 2.
"""
