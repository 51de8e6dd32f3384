# Figures and report tables, drawn from the NetCDF files alone (never refitting anything),
# so restyling a figure reruns only its plot job. Include after every rule file whose
# outputs these rules draw.
SWEEP_SCENARIOS = [s for s in SCENARIOS if "sweep" in config["implications"]["scenarios"][s]]
LAUNCH_SCENARIOS = [s for s in SCENARIOS if s not in SWEEP_SCENARIOS]
#: Figs. 9-10 switch on by themselves once a rule (workflow/rules/stronge.smk) writes stronge.nc.
HAS_STRONGE = rule_writes("results/{dataset}/stronge.nc")

TARGETS += expand("results/{dataset}/figures/{fig}.png", dataset=DATASETS, fig=["fig3", "fig4", "fig5", "fig6"])
TARGETS += expand("results/{dataset}/paper_comparison.html", dataset=DATASETS)
TARGETS += expand("results/implications/figures/{scenario}_fig11{part}.png", scenario=SWEEP_SCENARIOS, part=["a", "b"])
TARGETS += expand("results/implications/figures/{scenario}_launch.png", scenario=LAUNCH_SCENARIOS)
if "results/implications/paper_comparison.csv" in TARGETS:
    TARGETS.append("results/implications/paper_comparison.html")
if HAS_STRONGE:
    TARGETS += expand("results/{dataset}/figures/{fig}.png", dataset=DATASETS, fig=["fig9a", "fig9b", "fig10"])


rule plot_fig3:
    """Draw Fig. 3: normalised spin against launch angle, fitted and published slopes."""
    input:
        impacts=rules.reconstruct.output.impacts,
        fit=rules.fit_ex.output.fit,
        code=code("plot.py"),
    output:
        png=report(
            "results/{dataset}/figures/fig3.png",
            caption="../report/fig3.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 3", "shows": "normalised spin vs theta"},
        ),
        numbers="results/{dataset}/figures/fig3.rst",
    params:
        figure="fig3",
    log:
        "results/{dataset}/logs/plot_fig3.log",
    script:
        "../scripts/plot.py"


rule plot_fig4:
    """Draw Fig. 4: normalised exit speed against launch angle, fitted and published slopes."""
    input:
        impacts=rules.reconstruct.output.impacts,
        fit=rules.fit_ex.output.fit,
        code=code("plot.py"),
    output:
        png=report(
            "results/{dataset}/figures/fig4.png",
            caption="../report/fig4.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 4", "shows": "normalised exit speed vs theta"},
        ),
        numbers="results/{dataset}/figures/fig4.rst",
    params:
        figure="fig4",
    log:
        "results/{dataset}/logs/plot_fig4.log",
    script:
        "../scripts/plot.py"


rule plot_fig5:
    """Draw Fig. 5: spin against the bracket of Eq. omega, slopes 1 + e_x and the unit slope."""
    input:
        impacts=rules.reconstruct.output.impacts,
        fit=rules.fit_ex.output.fit,
        code=code("plot.py"),
    output:
        png=report(
            "results/{dataset}/figures/fig5.png",
            caption="../report/fig5.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 5", "shows": "spin vs Eq. omega bracket (e_x)"},
        ),
        numbers="results/{dataset}/figures/fig5.rst",
    params:
        figure="fig5",
    log:
        "results/{dataset}/logs/plot_fig5.log",
    script:
        "../scripts/plot.py"


rule plot_fig6:
    """Draw Fig. 6: tan(psi - theta) against tan psi, fitted and published slopes (Eq. ratio)."""
    input:
        impacts=rules.reconstruct.output.impacts,
        fit=rules.fit_ex.output.fit,
        code=code("plot.py"),
    output:
        png=report(
            "results/{dataset}/figures/fig6.png",
            caption="../report/fig6.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 6", "shows": "tan(psi - theta) vs tan psi"},
        ),
        numbers="results/{dataset}/figures/fig6.rst",
    params:
        figure="fig6",
    log:
        "results/{dataset}/logs/plot_fig6.log",
    script:
        "../scripts/plot.py"


rule plot_fig9:
    """Draw Fig. 9: Stronge's model fitted to the data (a) and extrapolated to 85 deg (b)."""
    input:
        stronge="results/{dataset}/stronge.nc",
        code=code("plot.py"),
    output:
        fig9a=report(
            "results/{dataset}/figures/fig9a.png",
            caption="../report/fig9a.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 9a", "shows": "Stronge's model, fitted eta^2"},
        ),
        fig9b=report(
            "results/{dataset}/figures/fig9b.png",
            caption="../report/fig9b.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 9b", "shows": "Stronge's model extrapolated"},
        ),
        numbers="results/{dataset}/figures/fig9.rst",
    params:
        figure="fig9",
    log:
        "results/{dataset}/logs/plot_fig9.log",
    script:
        "../scripts/plot.py"


rule plot_fig10:
    """Draw Fig. 10: Stronge's model's forces and tangential velocity against time at psi = 30 deg."""
    input:
        stronge="results/{dataset}/stronge.nc",
        code=code("plot.py"),
    output:
        png=report(
            "results/{dataset}/figures/fig10.png",
            caption="../report/fig10.rst",
            category="Dataset {dataset}",
            subcategory="Figures",
            labels={"figure": "Fig. 10", "shows": "time histories of Stronge's model"},
        ),
        numbers="results/{dataset}/figures/fig10.rst",
    params:
        figure="fig10",
    log:
        "results/{dataset}/logs/plot_fig10.log",
    script:
        "../scripts/plot.py"


rule plot_fig11:
    """Draw Fig. 11 for a D-sweep scenario: exit speed and spin vs D (a), trajectories (b)."""
    input:
        scenario=rules.implications.output.scenario,
        code=code("plot.py"),
    output:
        fig11a=report(
            "results/implications/figures/{scenario}_fig11a.png",
            caption="../report/fig11a.rst",
            category="Implications",
            subcategory="{scenario}",
            labels={"figure": "Fig. 11a", "scenario": "{scenario}"},
        ),
        fig11b=report(
            "results/implications/figures/{scenario}_fig11b.png",
            caption="../report/fig11b.rst",
            category="Implications",
            subcategory="{scenario}",
            labels={"figure": "Fig. 11b", "scenario": "{scenario}"},
        ),
        numbers="results/implications/figures/{scenario}_fig11.rst",
    params:
        figure="fig11",
    log:
        "results/implications/logs/plot_fig11_{scenario}.log",
    script:
        "../scripts/plot.py"


rule plot_launch:
    """Draw a launch-conditions scenario: trajectories and carry against launch angle."""
    input:
        scenario=rules.implications.output.scenario,
        code=code("plot.py"),
    output:
        png=report(
            "results/implications/figures/{scenario}_launch.png",
            caption="../report/launch.rst",
            category="Implications",
            subcategory="{scenario}",
            labels={"figure": "carry", "scenario": "{scenario}"},
        ),
        numbers="results/implications/figures/{scenario}_launch.rst",
    params:
        figure="launch",
    log:
        "results/implications/logs/plot_launch_{scenario}.log",
    script:
        "../scripts/plot.py"


rule comparison_html:
    """Render a paper-comparison table as HTML for the report."""
    input:
        csv="results/{source}/paper_comparison.csv",
        code=code("comparison_html.py"),
    output:
        html=report(
            "results/{source}/paper_comparison.html",
            caption="../report/comparison.rst",
            category="Paper comparison",
            labels={"table": "{source}"},
        ),
    wildcard_constraints:
        source="|".join(DATASETS + ["implications"]),
    log:
        "results/{source}/logs/comparison_html.log",
    script:
        "../scripts/comparison_html.py"
