"""The workflow run end to end through Snakemake: default and lab runs, faults, red-team cases, reruns."""
