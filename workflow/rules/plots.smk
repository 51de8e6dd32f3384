# Figures and report tables, drawn from the NetCDF files alone (never refitting anything),
# so restyling a figure reruns only its plot job.
#: Figs. 3-6: one definition, one rule each (name, what the figure shows in the report).
DATASET_FIGURES = {
    "fig3": "normalised spin vs theta",
    "fig4": "normalised exit speed vs theta",
    "fig5": "spin vs Eq. omega bracket (e_x)",
    "fig6": "tan(psi - theta) vs tan psi",
}

for _fig, _shows in DATASET_FIGURES.items():

    rule:
        name:
            f"plot_{_fig}"
        input:
            impacts=rules.reconstruct.output.impacts,
            fit=rules.fit_ex.output.fit,
            code=code("plot.py"),
        output:
            png=report(
                f"{R}/{{dataset}}/figures/{_fig}.png",
                caption=f"../report/{_fig}.rst",
                category="Dataset {dataset}",
                subcategory="Figures",
                labels={"figure": f"Fig. {_fig[3:]}", "shows": _shows},
            ),
            numbers=f"{R}/{{dataset}}/figures/{_fig}.rst",
        log:
            f"{R}/{{dataset}}/logs/plot_{_fig}.log",
        conda:
            ENV
        params:
            figure=_fig,
        script:
            "../scripts/plot.py"


rule plot_fig9:
    """Draw Fig. 9: Stronge's model fitted to the data (a) and extrapolated to 85 deg (b)."""
    input:
        stronge=rules.fit_stronge.output.stronge,
        code=code("plot.py"),
    output:
        fig9a=report(
            f"{R}/{{dataset}}/figures/fig9a.png",
            caption="../report/fig9a.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 9a", "shows": "Stronge's model, fitted eta^2"},
        ),
        fig9b=report(
            f"{R}/{{dataset}}/figures/fig9b.png",
            caption="../report/fig9b.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 9b", "shows": "Stronge's model extrapolated"},
        ),
        numbers=f"{R}/{{dataset}}/figures/fig9.rst",
    log:
        f"{R}/{{dataset}}/logs/plot_fig9.log",
    conda:
        ENV
    params:
        figure="fig9",
    script:
        "../scripts/plot.py"


rule plot_fig10:
    """Draw Fig. 10: Stronge's model's forces and tangential velocity against time at stronge.psi_history_deg."""
    input:
        stronge=rules.fit_stronge.output.stronge,
        code=code("plot.py"),
    output:
        png=report(
            f"{R}/{{dataset}}/figures/fig10.png",
            caption="../report/fig10.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 10", "shows": "time histories of Stronge's model"},
        ),
        numbers=f"{R}/{{dataset}}/figures/fig10.rst",
    log:
        f"{R}/{{dataset}}/logs/plot_fig10.log",
    conda:
        ENV
    params:
        figure="fig10",
    script:
        "../scripts/plot.py"


rule plot_fig11:
    """Draw Fig. 11 for a D-sweep scenario: exit speed and spin vs D (a), trajectories (b)."""
    input:
        scenario=rules.implications.output.scenario,
        code=code("plot.py"),
    output:
        fig11a=report(
            f"{R}/implications/figures/{{scenario}}_fig11a.png",
            caption="../report/fig11a.rst",
            category="Implications",
            subcategory="{scenario}",
            labels={"figure": "Fig. 11a", "scenario": "{scenario}"},
        ),
        fig11b=report(
            f"{R}/implications/figures/{{scenario}}_fig11b.png",
            caption="../report/fig11b.rst",
            category="Implications",
            subcategory="{scenario}",
            labels={"figure": "Fig. 11b", "scenario": "{scenario}"},
        ),
        numbers=f"{R}/implications/figures/{{scenario}}_fig11.rst",
    log:
        f"{R}/implications/logs/plot_fig11_{{scenario}}.log",
    conda:
        ENV
    params:
        figure="fig11",
    script:
        "../scripts/plot.py"


rule plot_launch:
    """Draw a launch-conditions scenario: trajectories and carry against launch angle."""
    input:
        scenario=rules.implications.output.scenario,
        code=code("plot.py"),
    output:
        png=report(
            f"{R}/implications/figures/{{scenario}}_launch.png",
            caption="../report/launch.rst",
            category="Implications",
            subcategory="{scenario}",
            labels={"figure": "carry", "scenario": "{scenario}"},
        ),
        numbers=f"{R}/implications/figures/{{scenario}}_launch.rst",
    log:
        f"{R}/implications/logs/plot_launch_{{scenario}}.log",
    conda:
        ENV
    params:
        figure="launch",
    script:
        "../scripts/plot.py"


rule comparison_html:
    """Render a paper-comparison table as HTML for the report."""
    input:
        csv=f"{R}/{{source}}/paper_comparison.csv",
        code=code("comparison_html.py"),
    output:
        html=report(
            f"{R}/{{source}}/paper_comparison.html",
            caption="../report/comparison.rst",
            category="Paper comparison",
            labels={"table": "{source}"},
        ),
    log:
        f"{R}/{{source}}/logs/comparison_html.log",
    wildcard_constraints:
        source="|".join(DATASETS + ["implications"]),
    conda:
        ENV
    script:
        "../scripts/comparison_html.py"
