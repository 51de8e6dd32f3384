"""The workflow's input functions, target lists and resource plans, from the validated config.

Snakemake's rule files hold rules; what they compute about the config (each rule's inputs,
params, memory and time, and the lists of targets) is this module's, so that it is read,
tested and changed as Python (tests/test_workflow_inputs.py). ``workflow/rules/common.smk``
builds one :class:`WorkflowInputs` from the validated config and hands its methods to the
rules: each method that takes ``wildcards`` is an input, params or resources function.
"""

from __future__ import annotations

import math
import os
from argparse import Namespace
from pathlib import Path
from typing import TYPE_CHECKING

from .config_checks import BYTES_PER_CASE, STUDY_BYTES_PER_REPLICATE, impact_bytes, scenario_tables, study_impacts
from .datasets import films, renders
from .pipeline.codedeps import module_files
from .pipeline.guards import results_root
from .pipeline.provenance import sha256_file
from .tracks.data import CAMERAS, camera_block, clips_block, tool_file_extensions
from .video.plan import (
    LARGEST_FRAME_BYTES,
    Clip,
    batch_mem_mb,
    batch_runtime_min,
    file_frames,
    folder_clips,
    plan_batches,
    rendered_clips,
)

if TYPE_CHECKING:
    from .studies.settings import StudySettings

#: Every figure of a dataset ({results}/{dataset}/figures/).
DATASET_FIGURES = ("fig3", "fig4", "fig5", "fig6", "fig9a", "fig9b", "fig10")


def existing(path: str) -> str | list:
    """Return ``path`` as an input when it is a file, none when it is missing or not a file.

    So only this dataset's job fails, with a message that says what the path is (not the whole DAG).
    """
    return path if Path(path).is_file() else []


def file_hashes(files: dict[str, str]) -> dict[str, str]:
    """Return the sha256 of each of ``files`` (name -> path).

    A param of the rules that read them, so that their jobs rerun when the content changes, even to
    a copy with an older timestamp (cp -p, tar, rsync -a).
    """
    return {k: sha256_file(v) if Path(v).is_file() else "not a file" for k, v in files.items()}


class WorkflowInputs:
    """The rules' view of one validated config (``basedir``: the workflow's folder, for its scripts).

    ``wildcards``: Snakemake's wildcards of a job (or any object with the same attributes, e.g.
    an :class:`argparse.Namespace`).
    """

    def __init__(self, config: dict, basedir: str | Path) -> None:
        self.config = config
        self.scripts = Path(basedir) / "workflow" / "scripts"
        #: The run's results folder (config ``results``; default ``results``): every product's path starts with it.
        self.results = results_root(config)
        self.datasets = sorted(config["datasets"])
        self.tracked = [d for d in self.datasets if self.uses_tracks(d)]
        #: The datasets whose tracks come from clips (rule import_clips); the others' tool files: import_tracks.
        self.filmed = [d for d in self.tracked if self.from_clips(d)]
        self.not_filmed = [d for d in self.datasets if d not in self.filmed]
        self.scenarios = sorted(config.get("implications", {}).get("scenarios", {}))
        scenarios = config.get("implications", {}).get("scenarios", {})
        self.sweep_scenarios = [s for s in self.scenarios if "sweep" in scenarios[s]]
        self.launch_scenarios = [s for s in self.scenarios if s not in self.sweep_scenarios]
        self.all_studies = sorted(config.get("studies") or {})
        self.studies = [s for s in self.all_studies if not config["studies"][s]["on_request"]]
        self._batches: dict[str, list[list[Clip]]] = {}
        self._study_settings: dict[str, StudySettings] = {}

    # -- code and datasets ----------------------------------------------------------------

    def code(self, script: str) -> list[str]:
        """Return the package modules a script imports (so editing them reruns the rule)."""
        here = os.path.join(os.getcwd(), "")  # relative to the working folder where inside it (string ops: parse time)
        files = module_files(str(self.scripts / script))
        return [f[len(here) :] if f.startswith(here) else f for f in files]

    def dataset_config(self, wildcards: Namespace) -> dict:
        """Return the dataset's validated config block."""
        return self.config["datasets"][wildcards.dataset]

    def get_synthetic_settings(self, wildcards: Namespace) -> dict:
        """Return the dataset's ``synthetic`` block (the simulate rule's params)."""
        return self.dataset_config(wildcards)["synthetic"]

    def data_files(self, wildcards: Namespace) -> dict[str, str]:
        """Return the dataset's data files as the config names them: impacts (measured), balls, bats, tracks."""
        ds = self.dataset_config(wildcards)
        tables = self.config["tables"]
        files = {"balls": ds.get("balls", tables["balls"]), "bats": ds.get("bats", tables["bats"])}
        if "impacts" in ds:
            files["impacts"] = ds["impacts"]
        if "tracks" in ds:
            if "file" in ds["tracks"]:
                files["tracks"] = ds["tracks"]["file"]
            files["tracks_impacts"] = ds["tracks"]["impacts"]
        return files

    def get_balls_table(self, wildcards: Namespace) -> str | list:
        """Return the dataset's ball table as an input (:func:`existing`)."""
        return existing(self.data_files(wildcards)["balls"])

    def get_bats_table(self, wildcards: Namespace) -> str | list:
        """Return the dataset's bat table as an input (:func:`existing`)."""
        return existing(self.data_files(wildcards)["bats"])

    def data_hashes(self, wildcards: Namespace) -> dict[str, str]:
        """Return the sha256 of each data file of a dataset (:func:`file_hashes`)."""
        return file_hashes(self.data_files(wildcards))

    def is_measured(self, name: str) -> bool:
        """Return whether a dataset is measured (it names its impacts file; a synthetic one has ``synthetic``)."""
        return "impacts" in self.config["datasets"][name]

    def get_measured_impacts(self, wildcards: Namespace) -> str | list:
        """Return a measured dataset's impacts file as an input (:func:`existing`)."""
        return existing(self.dataset_config(wildcards)["impacts"])

    def uses_tracks(self, name: str) -> bool:
        """Return whether a dataset starts from raw camera tracks (reduce.nc is its source)."""
        d = self.config["datasets"][name]
        return "tracks" in d or renders(d)

    def from_clips(self, name: str) -> bool:
        """Return whether a dataset's tracks come from clips (a ``format: video`` folder, or filmed impacts)."""
        d = self.config["datasets"][name]
        return films(d) or d.get("tracks", {}).get("format") == "video"

    def dataset_kind(self, name: str) -> str:
        """Return what a dataset is, in words (the report's front page)."""
        if self.uses_tracks(name):
            return "camera tracks" if "tracks" in self.config["datasets"][name] else "synthetic, rendered camera tracks"
        return "measured" if self.is_measured(name) else "synthetic"

    def get_source(self, wildcards: Namespace) -> str:
        """Return the first product of a dataset: its experiment, its measured impacts or its reduced tracks."""
        if self.uses_tracks(wildcards.dataset):  # raw camera tracks: workflow/rules/tracks.smk
            return f"{self.results}/{wildcards.dataset}/reduce.nc"
        stage = "ingest" if self.is_measured(wildcards.dataset) else "simulate"
        return f"{self.results}/{wildcards.dataset}/{stage}.nc"

    # -- camera tracks --------------------------------------------------------------------

    def get_render_settings(self, wildcards: Namespace) -> dict:
        """Return the dataset's ``render`` block (the render rule's params)."""
        return self.dataset_config(wildcards)["render"]

    def get_tracks_inputs(self, wildcards: Namespace) -> dict:
        """Return the reduce rule's track inputs.

        A lab's tracks and impacts files, its imported tool files (imported_tracks.nc and the
        camera settings found in them), or the rendered tracks.nc (both .nc hold their impact table).
        """
        d = self.dataset_config(wildcards)
        if ("tracks" in d and "dir" in d["tracks"]) or films(d):
            out = f"{self.results}/{wildcards.dataset}/imported"
            return {"tracks": f"{out}_tracks.nc", "cameras": f"{out}_cameras.yaml"}
        if "tracks" in d:  # a missing file fails this dataset's reduce job only (existing), not the DAG
            return {"tracks": existing(d["tracks"]["file"]), "impacts": existing(d["tracks"]["impacts"])}
        return {"tracks": f"{self.results}/{wildcards.dataset}/tracks.nc"}

    def get_tool_files(self, wildcards: Namespace) -> dict:
        """Return the tool files of a dataset whose tracks block names a folder (dir), and its impacts file.

        A dataset that films its impacts (``render.video``): the folder of clips the render_clips rule writes.
        """
        d = self.dataset_config(wildcards)
        if films(d):
            return {"files": self.clips_dir(wildcards)}
        t = d["tracks"]
        exts = tool_file_extensions(t.get("format"))
        found = sorted(str(p) for p in Path(t["dir"]).glob("*") if p.is_file() and p.suffix.lower() in exts)
        # a Photron header's frames are in the .mraw beside it: an input too, so new frames rerun the import
        mraw = [p.with_suffix(".mraw") for p in map(Path, found) if p.suffix.lower() in (".cih", ".cihx")]
        found += sorted(str(p) for p in mraw if p.is_file())  # a missing one: the import names it
        return {"files": found, "impacts": existing(t["impacts"])}

    def tool_file_hashes(self, wildcards: Namespace) -> dict[str, str]:
        """Return the sha256 of every tool file of a ``tracks.dir`` folder and of the dataset's tables.

        A tool file replaced by other content reruns the import, whatever its timestamp (:func:`file_hashes`).
        Clips: the dataset's tables only (each clip's sha256 is a param of its batch, :meth:`batch_hashes`,
        whose new batch file reruns the import).
        """
        if self.from_clips(wildcards.dataset):
            return self.data_hashes(wildcards)
        files = {Path(f).name: f for f in self.get_tool_files(wildcards)["files"]}
        return {**self.data_hashes(wildcards), **file_hashes(files)}

    def get_import_settings(self, wildcards: Namespace) -> dict:
        """Return the dataset's ``tracks`` block (the import rule's params); filmed impacts: the block of the clips."""
        d = self.dataset_config(wildcards)
        if films(d):
            return clips_block(d["render"], self.clips_dir(wildcards))
        return d["tracks"]

    def clips_dir(self, wildcards: Namespace) -> str:
        """Return the folder of a filmed dataset's clips (the render_clips rule's output)."""
        return f"{self.results}/{wildcards.dataset}/clips"

    # -- clips tracked in batches (ballbat.video.plan) ---------------------------------------

    def clip_batches(self, name: str) -> list[list[Clip]]:
        """Return the batches of a dataset's clips (``video.clips_per_job`` each), planned once a run.

        A lab's folder as the import lists it; a filmed experiment's clips named from its config.
        """
        if name not in self._batches:
            d = self.config["datasets"][name]
            block = self.get_import_settings(Namespace(dataset=name))
            if films(d):
                clips = rendered_clips(block["dir"], self._n_impacts(d), d["render"]["video"]["format"])
            else:
                clips = folder_clips(block)
            self._batches[name] = plan_batches(clips, block["video"]["clips_per_job"])
        return self._batches[name]

    def get_clip_batch_files(self, wildcards: Namespace) -> list[str]:
        """Return the batch files of a dataset's clips (rule track_clips's outputs; import_clips gathers them)."""
        n = len(self.clip_batches(wildcards.dataset))
        return [f"{self.results}/{wildcards.dataset}/clip_tracks/batch_{k}.nc" for k in range(n)]

    def _batch(self, wildcards: Namespace) -> list[Clip]:
        batches = self.clip_batches(wildcards.dataset)
        k = int(wildcards.batch)
        if k >= len(batches):
            raise ValueError(
                f"dataset {wildcards.dataset}: no batch {k} of its clips ({len(batches)} batches, numbered from 0)"
            )
        return batches[k]

    def get_batch_clips(self, wildcards: Namespace) -> dict:
        """Return a batch's inputs: its clips (a Photron header's .mraw beside it) and the impacts table.

        A filmed experiment: the folder of clips rule render_clips writes (the impacts table in it).
        """
        d = self.dataset_config(wildcards)
        if films(d):
            return {"clips": self.clips_dir(wildcards)}
        paths = [p for _, _, p in self._batch(wildcards)]
        mraw = [str(Path(p).with_suffix(".mraw")) for p in paths if Path(p).suffix.lower() in (".cih", ".cihx")]
        return {"clips": paths + [m for m in mraw if Path(m).is_file()], "impacts": existing(d["tracks"]["impacts"])}

    def get_tracker_settings(self, wildcards: Namespace) -> dict:
        """Return what a batch's tracker reads (rule track_clips's params): clips, scales, markers, impacts table."""
        block = self.get_import_settings(wildcards)
        return {
            "clips": [list(c) for c in self._batch(wildcards)],
            "m_per_px": {c: (block["cameras"].get(c) or {}).get("m_per_px") for c in CAMERAS},
            "video": {k: block["video"][k] for k in ("dot_radius_mm", "marker_radius_mm")},
            "impacts": block["impacts"],
            "where": self.get_reduce_where(wildcards),
        }

    def batch_hashes(self, wildcards: Namespace) -> dict[str, str]:
        """Return the sha256 of a batch's clips and of the dataset's tables: a changed clip reruns its batch only.

        A filmed experiment's clips are rule render_clips's, rebuilt by their own inputs: the tables' only.
        """
        if films(self.dataset_config(wildcards)):
            return self.data_hashes(wildcards)
        files = {Path(f).name: f for f in self.get_batch_clips(wildcards)["clips"]}
        return {**self.data_hashes(wildcards), **file_hashes(files)}

    def clip_batch_mem_mb(self, wildcards: Namespace) -> int:
        """Return a batch job's memory, MB, from its largest frame (the tracker streams: not from a clip's length).

        A filmed experiment's frames are its cameras'; a lab's are not known before the job: the largest assumed.
        """
        d = self.dataset_config(wildcards)
        if not films(d):
            return batch_mem_mb(LARGEST_FRAME_BYTES)
        cams, bits = d["render"]["cameras"], d["render"]["video"]["bit_depth"]
        return batch_mem_mb(max(cams[c]["width_px"] * cams[c]["height_px"] for c in CAMERAS) * (1 if bits <= 8 else 2))

    def clip_batch_runtime(self, wildcards: Namespace) -> int:
        """Return a batch job's time limit, minutes, from its frames.

        A filmed experiment: its cameras' longest clips; a lab's: bounded by its files' sizes.
        """
        d = self.dataset_config(wildcards)
        if films(d):
            cams = d["render"]["cameras"]
            return batch_runtime_min(sum(cams[cam]["max_frames"] for _, cam, _ in self._batch(wildcards)))
        return batch_runtime_min(file_frames(self.get_batch_clips(wildcards)["clips"]))

    def get_reduce_settings(self, wildcards: Namespace) -> dict:
        """Return the camera block the reduction reads (of ``tracks``, or of ``render``)."""
        d = self.dataset_config(wildcards)
        return camera_block(d["tracks"] if "tracks" in d else d["render"])

    def get_reduce_where(self, wildcards: Namespace) -> str:
        """Return the config key the reduction's messages name."""
        key = "tracks" if "tracks" in self.dataset_config(wildcards) else "render"
        return f"config datasets.{wildcards.dataset}.{key}"

    # -- resources ------------------------------------------------------------------------

    def dataset_mem_mb(self, wildcards: Namespace) -> int:
        """Return the memory a dataset's job may need, MB.

        Over a 500 MB base, 4 kB per impact (measured ~1 kB), 50 kB per impact rendered as camera
        tracks (measured 35 kB).
        """
        d = self.dataset_config(wildcards)
        n = self._n_impacts(d) if d.get("synthetic") else 10_000
        return 500 + n * impact_bytes(d) // 1_000_000

    @staticmethod
    def _n_impacts(d: dict) -> int:
        """Return the impacts of a synthetic dataset's block (its ``synthetic.impacts`` counts)."""
        return sum(sum(bats.values()) for bats in d["synthetic"]["impacts"].values())

    def scenario_mem_mb(self, wildcards: Namespace) -> int:
        """Return the memory a scenario's job may need, MB: 60 kB per case (measured 52-59 kB) over 500 MB."""
        sc = self.get_scenario(wildcards)
        if "sweep" in sc:
            n = int(sc["sweep"]["D_in"]["num"])
        else:
            sizes = [len(v) if isinstance(v, list) else 1 for k, v in sc["launch"].items() if k != "combine"]
            n = math.prod(sizes) if sc["launch"]["combine"] == "grid" else max(sizes)
        return 500 + n * BYTES_PER_CASE // 1_000_000

    # -- scenarios ------------------------------------------------------------------------

    def get_scenario(self, wildcards: Namespace) -> dict:
        """Return the scenario's config block."""
        return self.config["implications"]["scenarios"][wildcards.scenario]

    def get_scenario_tables(self, wildcards: Namespace) -> dict[str, str]:
        """Return the scenario's property tables: its dataset's where they hold its bat and ball, else ``tables``."""
        return scenario_tables(self.config, self.get_scenario(wildcards))

    def scenario_hashes(self, wildcards: Namespace) -> dict[str, str]:
        """Return the sha256 of the scenario's property tables (:func:`file_hashes`)."""
        return file_hashes(self.get_scenario_tables(wildcards))

    def workbook_scenarios(self) -> list[str]:
        """Return the scenario files of the implications workbook: this run's, and the earlier ones of its folder.

        An earlier run of the same results folder with another config (a lab's own scenario) left its
        ``implications/{name}.nc``; the workbook keeps its sheet (a scenario file the workflow wrote,
        :func:`.pipeline.guards.written_by_workflow`; not one put there by hand, nor a damaged one).
        """
        from .pipeline.guards import product_problem, written_by_workflow

        folder = Path(self.results) / "implications"
        ours = [f"{folder.as_posix()}/{s}.nc" for s in self.scenarios]
        earlier = [
            p.as_posix()
            for p in sorted(folder.glob("*.nc"))
            if p.stem not in self.scenarios and written_by_workflow(p) and product_problem(p) is None
        ]
        return sorted(ours + earlier, key=lambda f: Path(f).stem)

    def get_scenario_fit(self, wildcards: Namespace) -> dict:
        """Return fit_ex.nc of the dataset whose e_x the scenario uses (none by default)."""
        name = self.get_scenario(wildcards).get("e_x_from_dataset")
        return {"fit": f"{self.results}/{name}/fit_ex.nc"} if name else {}

    def final_targets(self) -> list[str]:
        """Return everything a default run makes.

        Every dataset's intermediate files, fits, figures and tables, and every scenario's (rule all
        asks for these; an intermediate deleted by hand is therefore rebuilt).
        """
        per_dataset = ["normalize.nc", "reconstruct.nc", "fit_ex.nc", "stronge.nc"]
        per_dataset += ["paper_comparison.csv", "paper_comparison.html", "results.xlsx"]
        per_dataset += [f"figures/{fig}.png" for fig in DATASET_FIGURES]
        r, imp = self.results, f"{self.results}/implications"
        targets = [self.get_source(Namespace(dataset=d)) for d in self.datasets]
        targets += [f"{r}/{d}/figures/tracks_{fig}.png" for d in self.tracked for fig in ("impacts", "summary")]
        targets += [f"{r}/{d}/figures/clips_{fig}.png" for d in self.filmed for fig in ("contact_sheet", "quality")]
        targets += [f"{r}/{d}/{f}" for d in self.datasets for f in per_dataset]
        targets += [f"{imp}/{s}.nc" for s in self.scenarios]
        targets += [f"{imp}/results.xlsx"] if self.scenarios else []
        targets += [f"{imp}/figures/{s}_fig11{p}.png" for s in self.sweep_scenarios for p in "ab"]
        targets += [f"{imp}/figures/{s}_launch.png" for s in self.launch_scenarios]
        if "paper" in self.sweep_scenarios:  # the paper's own scenario is compared with Sec. V.B
            targets += [f"{imp}/paper_comparison.csv", f"{imp}/paper_comparison.html"]
        return targets

    def league_targets(self) -> list[str]:
        """Return the league products of a run (rule all), none unless it has something to compare.

        Something to compare: more than one dataset, or a dataset with more than one bat of a ball
        (a synthetic dataset's ``impacts`` say; a measured one's file is read only by its jobs, so
        it counts). Here, not in :mod:`ballbat.league`, so that Snakemake's start does not import
        the statistics (scipy.stats: 1.4 s a start).
        """

        def several_bats(block: dict) -> bool:
            if "synthetic" not in block:
                return True
            return max(sum(1 for n in per.values() if n) for per in block["synthetic"]["impacts"].values()) > 1

        datasets = self.config["datasets"]
        if len(datasets) > 1 or any(several_bats(b) for b in datasets.values()):
            return [
                f"{self.results}/league.nc",
                f"{self.results}/league.csv",
                f"{self.results}/league.xlsx",
                f"{self.results}/figures/league_forest.png",
            ]
        return []

    # -- replicate studies ----------------------------------------------------------------

    def study_settings(self, name: str) -> StudySettings:
        """Return study ``name``'s settings (built once: the rules' functions ask for them some 20 times a start)."""
        from .studies.settings import StudySettings

        if name not in self._study_settings:
            self._study_settings[name] = StudySettings.from_config(self.config, name)
        return self._study_settings[name]

    def get_study_config(self, wildcards: Namespace) -> dict:
        """Return everything a study's results depend on (its, its dataset's and the chain's settings)."""
        from .studies.settings import study_block

        return study_block(self.config, wildcards.study)

    def _study_dataset(self, wildcards: Namespace) -> Namespace:
        return Namespace(dataset=self.config["studies"][wildcards.study]["dataset"])

    def study_hashes(self, wildcards: Namespace) -> dict[str, str]:
        """Return the sha256 of a study's property tables (a changed table reruns the study)."""
        return self.data_hashes(self._study_dataset(wildcards))

    def get_study_balls(self, wildcards: Namespace) -> str | list:
        """Return the ball table of the study's dataset as an input."""
        return self.get_balls_table(self._study_dataset(wildcards))

    def get_study_bats(self, wildcards: Namespace) -> str | list:
        """Return the bat table of the study's dataset as an input."""
        return self.get_bats_table(self._study_dataset(wildcards))

    def get_study_batches(self, wildcards: Namespace) -> list[str]:
        """Return the study's batch files."""
        n = self.study_settings(wildcards.study).n_batches
        return [f"{self.results}/studies/{wildcards.study}/batches/batch{b}.nc" for b in range(n)]

    def study_batch_mem_mb(self, wildcards: Namespace) -> int:
        """Return a batch job's memory, MB: one replicate at a time (measured ~180 MB at the paper's size)."""
        s = self.study_settings(wildcards.study)
        largest = study_impacts(s.dataset, s.parameter, s.values, s.truth_impacts)[0]
        return 500 + math.ceil(largest * impact_bytes(s.dataset) / 1e6)

    def study_truth_mem_mb(self, wildcards: Namespace) -> int:
        """Return a truth job's memory, MB: its point's large noise-free design (StudySettings.truth_mem_mb)."""
        return self.study_settings(wildcards.study).truth_mem_mb(int(wildcards.point))

    def study_aggregate_mem_mb(self, wildcards: Namespace) -> int:
        """Return the aggregate's memory, MB: every replicate's table (STUDY_BYTES_PER_REPLICATE) over 500 MB."""
        s = self.study_settings(wildcards.study)
        return 500 + math.ceil(s.total * STUDY_BYTES_PER_REPLICATE / 1e6)

    def study_batch_runtime(self, wildcards: Namespace) -> int:
        """Return a batch job's time, minutes: about a second per replicate of the paper's size, with room."""
        s = self.study_settings(wildcards.study)
        return max(10, math.ceil(s.batch_size * 2 / 60) + 5)

    def get_study_truth_points(self, wildcards: Namespace) -> list[str]:
        """Return the study's truth files, one per sweep point."""
        n = self.study_settings(wildcards.study).n_points
        return [f"{self.results}/studies/{wildcards.study}/truth/point{p}.nc" for p in range(n)]

    def study_truth_runtime(self, wildcards: Namespace) -> int:
        """Return a truth job's time, minutes (StudySettings.truth_runtime_min)."""
        return self.study_settings(wildcards.study).truth_runtime_min(int(wildcards.point))

    def study_targets(self, on_request: bool = False) -> list[str]:
        """Return every product of every study (of ``studies``, or with on_request ``studies_on_request``).

        Its truth and batches included, so that one deleted by hand is rebuilt (Snakemake does not
        rebuild a missing intermediate whose consumers are up to date). A one-parameter sweep has a
        design, a grid its grid figure.
        """
        targets = []
        for name in self.studies if not on_request else sorted(set(self.all_studies) - set(self.studies)):
            targets += [f"{self.results}/studies/{name}/coverage.{ext}" for ext in ("nc", "csv", "png")]
            sweep = self.config["studies"][name].get("sweep") or {}
            if "grid" in sweep:
                targets += [f"{self.results}/studies/{name}/grid.png"]
            elif sweep:
                targets += [f"{self.results}/studies/{name}/design.{ext}" for ext in ("nc", "csv", "png")]
            targets += [f"{self.results}/studies/{name}/truth.nc", *self.get_study_truth_points(Namespace(study=name))]
            targets += self.get_study_batches(Namespace(study=name))
        return targets
