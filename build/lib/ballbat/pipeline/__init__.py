"""Workflow plumbing, kept apart from the physics.

Config validation (:mod:`.config`), the package modules a rule depends on (:mod:`.codedeps`),
run logs (:mod:`.runlog`), atomic writes (:mod:`.atomic`), provenance records
(:mod:`.provenance`) and NetCDF input/output (:mod:`.ncio`). Nothing here knows any physics.
"""
