"""Stronge's lumped-parameter contact model (Sec. V.A of Kensrud et al. 2017).

:mod:`.model` is the closed-form solver, :mod:`.regimes` the regime codes and boundaries in
psi, :mod:`.reference` the numerical integrator the tests check the solver against,
:mod:`.fit` the eta^2 fit and :mod:`.analysis` the per-dataset analysis that the
``fit_stronge`` rule runs (``results/{dataset}/stronge.nc``).
"""
