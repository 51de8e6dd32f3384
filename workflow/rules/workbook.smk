rule workbook:
    """Write a dataset's results as a spreadsheet in the paper's units, with its provenance."""
    input:
        impacts=rules.reconstruct.output.impacts,
        fit=rules.fit_ex.output.fit,
        stronge=rules.fit_stronge.output.stronge,
        comparison=rules.compare.output.csv,
        code=code("workbook.py"),
    output:
        xlsx=report(
            f"{R}/{{dataset}}/results.xlsx",
            caption="../report/workbook.rst",
            category="Dataset {dataset}",
            subcategory="Workbook",
            labels={"table": "results.xlsx"},
        ),
    log:
        f"{R}/{{dataset}}/logs/workbook.log",
    conda:
        ENV
    script:
        "../scripts/workbook.py"


rule implications_workbook:
    """Write every batted-ball scenario as a sheet of one spreadsheet (mph, deg, rpm, ft, s).

    Every scenario of the folder: this run's and those an earlier run of the folder left (their sheets stay).
    """
    input:
        scenarios=INPUTS.workbook_scenarios(),
        code=code("workbook.py"),
    output:
        xlsx=report(
            f"{R}/implications/results.xlsx",
            caption="../report/workbook.rst",
            category="Implications",
            subcategory="Workbook",
            labels={"table": "results.xlsx"},
        ),
    log:
        f"{R}/implications/logs/workbook.log",
    conda:
        ENV
    script:
        "../scripts/workbook.py"
