"""Console scripts: thin Hydra/argparse entry points. The work they start lives in the library
(:mod:`stylemotion.training`, :mod:`stylemotion.reproduction`, :mod:`stylemotion.evaluation.run`,
:mod:`stylemotion.segmentation_report`, :mod:`stylemotion.synthesis.generate`,
:mod:`stylemotion.datasets.convert`, :mod:`stylemotion.datasets.summary`), so notebooks can call it."""
