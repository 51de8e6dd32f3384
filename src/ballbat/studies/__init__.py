"""Replicate studies: the whole chain on many synthetic experiments (coverage and design).

A study takes a synthetic dataset's settings and runs the stages the workflow runs
(:mod:`ballbat.stages`: simulate; when the dataset renders camera tracks, render and reduce;
normalize, reconstruct, fit_ex; and Stronge's eta^2 fit,
:func:`ballbat.stronge.fit.fit_eta2`) on independent replicate experiments, in memory and
in batches (:func:`run_batch`: one process per batch, one NetCDF file per batch, nothing per
replicate). Seeds: replicate ``k`` draws its experiment and its tracks from
``numpy.random.SeedSequence(seed, spawn_key=(k,))``, the same ``k`` at every sweep point
(common random numbers: the sweep's points differ by their setting, not by their luck).

Every quantity of ``paper_comparison.csv`` with an uncertainty and a synthetic truth is
recorded (value, standard error, truth, degrees of freedom) in SI, as ``fit_ex.nc`` holds it,
with its unit (the coordinate ``units`` of the study's files); the tables (coverage.csv) print
them in paper_comparison.csv's units (:func:`display_unit`). The truth
of a fitted quantity is, as in the workflow, the same estimator applied to the noise-free
truth of the same replicate with the same weights; for eta^2 it is the eta^2 fitted to the
noise-free impacts (the synthetic experiment is not drawn from Stronge's model, so eta^2 has
no truth of its own).

:func:`coverage` measures, per sweep point and quantity: the bias in units of the standard
error, the ratio of the empirical spread to the mean reported standard error, and the
fraction of 68 % and 95 % intervals (Student's t with the fit's degrees of freedom) that
cover the truth, each with its uncertainty. :func:`design` turns a sweep into what a lab
needs before it books the machine: the spread of e_x per bat at each setting and the number
of impacts per bat needed to tell two bats ``delta_e_x`` apart.
"""
