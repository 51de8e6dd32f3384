"""Stronge's lumped-parameter contact model (Sec. V.A of Kensrud et al. 2017).

:mod:`.model` is the closed-form solver, :mod:`.regimes` the regime boundaries in psi,
:mod:`.fit` the eta^2 fit, :mod:`.analysis` the per-dataset analysis that the ``fit_stronge``
rule runs, and :mod:`.reference` an independent numerical integration (tests, benchmarks).
"""
