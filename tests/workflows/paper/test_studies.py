"""Study definitions, the runner, and the paper report decided from data."""
import json
import warnings

import numpy as np
import pytest

from qzs.errors import ParameterError
from qzs.model.registry import unit_of
from qzs.workflows.paper.report import CLAIMS, decide_claims, write_paper_outputs
from qzs.workflows.paper.studies import load_study, run_studies, shipped_studies


def test_every_shipped_study_loads_and_names_known_claims():
    studies = [load_study(p) for p in shipped_studies()]
    assert [s.name for s in studies] == ["spring", "stiction", "viscous", "pi_gains", "no_pi",
                                         "damping", "processing"]
    for study in studies:
        assert set(study.claims) <= set(CLAIMS)
    # every claim is decided by some study
    assert set(CLAIMS) == {c for s in studies for c in s.claims}


def test_the_shipped_views_take_the_default_frequency_axis():
    """The paper's figures draw frequency as every figure does (log): no view asks for
    another scale; ``--frequency-axis linear`` gives the paper's own axes."""
    for path in shipped_studies():
        assert all("frequency_scale" not in view for view in load_study(path).views)


def test_shipped_name_resolves():
    assert load_study("stiction").name == "stiction"


@pytest.mark.parametrize("text, match", [
    ("[study]\nname='x'\nkind='bode'\n", "`kind` must be one of"),
    ("[study]\nname='x'\nkind='transmissibility'\n", "defines no"),
    ("[study]\nname='x'\nkind='transmissibility'\n[[case]]\nlabel='a'\nstiction=3\n",
     "case 1: unknown parameter 'stiction'"),
    ("[study]\nname='x'\nkind='transmissibility'\n[[case]]\nlabel='a'\nmass=-3\n",
     "case 1: `mass` must be positive"),
    ("[study]\nname='x'\nkind='transmissibility'\n[[case]]\nlabel='a'\n[analysis]\nfft=3\n",
     r"unknown key\(s\) \['fft'\] in \[analysis\]"),
    ("[stuff]\n", r"unknown table\(s\) \['stuff'\]"),
    ("[study]\nname='x'\nkind='transmissibility'\n[[study.view]]\nfigure='f'\n"
     "frequency_range=[0.0, 20.0]\nfrequency_scale='semilog'\n[[case]]\nlabel='a'\n",
     r"'f' has frequency_scale = 'semilog'; use one of log, linear"),
])
def test_bad_study_files(tmp_path, text, match):
    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(ParameterError, match=match):
        load_study(path)


def test_missing_study_lists_the_shipped_ones():
    with pytest.raises(ParameterError, match="shipped studies are"):
        load_study("no-such-study")


@pytest.fixture(scope="module")
def quick_paper(tmp_path_factory):
    """The whole quick paper, with even shorter analysis settings to keep the suite fast."""
    import dataclasses

    studies = []
    for path in shipped_studies():
        study = load_study(path)
        analysis = {**study.analysis, "quick_fft_length": 8192, "quick_n_averages": 12}
        studies.append(dataclasses.replace(study, analysis=analysis))
    folder = tmp_path_factory.mktemp("paper")
    results = run_studies(studies, quick=True, workers=2, progress=False)
    verdicts = write_paper_outputs(results, folder, quick=True, wall_seconds=1.0, workers=2)
    return results, verdicts, folder


def test_figures_drawn_in_worker_processes_are_those_drawn_in_process(quick_paper, tmp_path):
    results, _, folder = quick_paper  # drawn by 2 worker processes (the default on 2 cores)
    write_paper_outputs(results, tmp_path, quick=True, wall_seconds=1.0, workers=1)
    drawn = sorted(p.name for p in folder.glob("*.png"))
    assert drawn == sorted(p.name for p in tmp_path.glob("*.png"))
    assert len(drawn) == sum(len(r.study.views) or 1 for r in results)
    for name in drawn:
        assert (folder / name).read_bytes() == (tmp_path / name).read_bytes(), name


@pytest.mark.parametrize("workers", [0, 1.5, True, "2"])
def test_paper_outputs_refuse_bad_workers_before_writing(quick_paper, tmp_path, workers):
    results, _, _ = quick_paper
    with pytest.raises(ParameterError, match="`workers` must be an integer >= 1"):
        write_paper_outputs(results, tmp_path / "out", workers=workers)
    assert not (tmp_path / "out").exists()


def test_quick_report_decides_every_claim_from_data(quick_paper):
    results, verdicts, folder = quick_paper
    assert {v.claim for v in verdicts} == set(CLAIMS)
    html = (folder / "report.html").read_text()
    for verdict in verdicts:
        assert verdict.statement in html or verdict.statement.replace('"', "&quot;") in html
        # the evidence quotes numbers measured in this run
        assert any(ch.isdigit() for ch in verdict.evidence)
    document = json.loads((folder / "metrics.json").read_text())
    assert {c["claim"] for c in document["claims"]} == set(CLAIMS)
    for name in ("fig05_spring", "fig07_stiction", "fig08_viscous", "fig09_pi_gains",
                 "fig10_pi_gains_zoom", "fig12_no_pi", "fig13_processing", "fig14_damping",
                 "fig15_damping_zoom"):
        assert (folder / f"{name}.png").exists() and (folder / f"{name}.svg").exists()
        assert f"{name}.png" in html
    csv_lines = (folder / "metrics.csv").read_text().splitlines()
    assert csv_lines[0] == "# column names on line 2, units on line 3, data from line 4"
    assert len(csv_lines) == 3 + sum(len(r.cases) for r in results)
    assert "transmissibility_at_12_hz" in csv_lines[1]


def test_every_transmissibility_study_writes_its_curves_as_data(quick_paper):
    """Each study's curves file holds each case's simulated curve, bit for bit (NetCDF) and
    to 10 digits (CSV), with its parameters."""
    import pandas as pd
    import xarray as xr

    results, _, folder = quick_paper
    for result in results:
        nc, csv = folder / f"{result.study.name}_curves.nc", folder / f"{result.study.name}_curves.csv"
        if result.study.kind == "spring_characteristic":  # the points and the fitted law
            data, extra = xr.load_dataset(nc), result.cases[0].extra
            np.testing.assert_array_equal(data["force"].values, extra["force"])
            table = pd.read_csv(csv, comment="#", header=[0, 1])
            np.testing.assert_allclose(table[("displacement", "m")], extra["displacement"],
                                       rtol=1e-9)
            continue
        data = xr.load_dataset(nc)
        table = pd.read_csv(csv, comment="#", header=[0, 1])
        assert len(table) == data.sizes["case"] * data.sizes["frequency"]
        case = result.cases[-1]
        row = data.isel(case=len(result.cases) - 1 if result.study.kind != "processing" else 0)
        np.testing.assert_array_equal(row["magnitude"].values, case.magnitude)
        np.testing.assert_array_equal(row["phase"].values, case.phase)
        np.testing.assert_array_equal(row["trusted"].values.astype(bool), case.trusted)
        assert np.isfinite(case.phase[case.trusted]).all()
        for name, value in case.settings.items():
            assert float(row[name]) == value and data[name].attrs["units"] == unit_of(name)


def test_claims_follow_the_numbers(quick_paper):
    """Flip the data and the verdict must flip: decisions are not hard-coded."""
    import copy

    results, verdicts, _ = quick_paper
    by_claim = {v.claim: v for v in verdicts}
    assert by_claim["no_pi_stops"].reproduced is True
    assert by_claim["viscous_high_frequency"].reproduced is True
    tampered = copy.deepcopy(results)
    for r in tampered:
        if r.study.name == "no_pi":
            r.cases[0].stats["stop_contacts"] = 0
        if r.study.name == "viscous":  # swap the curves of the least and most damped cases
            first, last = r.cases[0], r.cases[-1]
            first.magnitude, last.magnitude = last.magnitude, first.magnitude
            first.trusted, last.trusted = last.trusted, first.trusted
    flipped = {v.claim: v for v in decide_claims(tampered)}
    assert flipped["no_pi_stops"].reproduced is False
    assert flipped["viscous_high_frequency"].reproduced is False
    # reordering the cases of a file changes nothing: trends follow the swept parameter
    reordered = copy.deepcopy(results)
    for r in reordered:
        r.cases.reverse()
    assert [v.label for v in decide_claims(reordered)] == [v.label for v in verdicts]


def test_resonance_masked_from_the_simulated_runs(quick_paper):
    """The payload is locked while the chirp is below 0.5 Hz (not above): masked."""
    results, verdicts, _ = quick_paper
    by_claim = {v.claim: v for v in verdicts}
    assert by_claim["resonance_masked"].label == "reproduced", by_claim["resonance_masked"]
    stiction = next(r for r in results if r.study.name == "stiction")
    for case in stiction.cases:
        assert case.stats["locked_fraction_below_half_hz"] >= 0.9
        assert case.stats["locked_fraction_below_half_hz"] > 2 * case.stats["locked_fraction"]


def test_no_metric_comes_from_an_untrusted_bin(quick_paper):
    """Every case of every study: metrics from trusted bins only, or NaN with a reason."""
    from test_trust import assert_metrics_from_trusted

    from qzs.analysis.spectral import transmissibility_metrics
    from qzs.defaults import REPORTED_FREQUENCIES

    results, _, _ = quick_paper
    checked = 0
    for result in results:
        if result.study.kind == "spring_characteristic":
            continue
        for case in result.cases:
            curves = [(case.frequency, case.magnitude, case.trusted, case.coherence,
                       case.metrics, case.reasons, None)]
            if result.study.kind == "processing":
                x = case.extra
                curves.append((x["frequency"], x["magnitude"], x["trusted"], x["coherence"],
                               x["metrics"], x["reasons"], x["highpass"]))
            for f, t, trusted, coherence, metrics, reasons, corner in curves:
                assert trusted.dtype == bool and trusted.shape == f.shape
                assert np.all(coherence[trusted] >= 0.9)
                if np.isfinite(metrics["resonance_frequency"]):  # never the 0.061 Hz artefact
                    i = int(np.flatnonzero(f == metrics["resonance_frequency"])[0])
                    assert trusted[i] and coherence[i] >= 0.9
                    assert metrics["resonance_frequency"] > metrics["trusted_from"]

                def recompute(values, f=f, trusted=trusted, corner=corner):
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        return transmissibility_metrics(
                            f, values, trusted=trusted, highpass_corner=corner,
                            at_frequencies=REPORTED_FREQUENCIES).to_dict()

                assert_metrics_from_trusted(f, t, trusted, metrics, reasons, recompute)
                checked += 1
    assert checked == 19


def test_outputs_say_why_a_metric_is_undefined(quick_paper):
    import csv

    results, _, folder = quick_paper
    lines = [line for line in (folder / "metrics.csv").open() if not line.startswith("#")]
    rows = list(csv.DictReader(lines[:1] + lines[2:]))  # the names, not the units row
    cases = [row for row in rows if row["study"] != "spring"]
    assert "resonance_frequency_reason" in rows[0]
    for row in cases:
        for name in ("resonance_frequency", "isolation_onset", "transmissibility_at_1_hz"):
            assert row[name] != "nan"
            assert (row[name] == "") == bool(row.get(f"{name}_reason")), (row["case"], name)
    document = json.loads((folder / "metrics.json").read_text())
    for study in document["studies"].values():
        for row in study["cases"]:
            for name, value in row.items():
                if value is None and f"{name}_reason" in row:
                    assert row[f"{name}_reason"]
    stiction = document["studies"]["stiction"]
    assert stiction["settings"]["solver"] == "ode3"
    assert stiction["settings"]["fft_length"] == 8192
    assert stiction["settings"]["window"] == "hann"


def test_report_states_settings_links_figures_and_hides_artefacts(quick_paper):
    import re

    _, _, folder = quick_paper
    text = (folder / "report.html").read_text()
    for setting in ("solver", "time step [s]", "chirp duration [s]", "FFT length [samples]",
                    "averages", "window", "sample rate [Hz]", "stiction_force [N]",
                    "pi_kp [N/m]"):
        assert setting in text, setting
    assert "figure img{width:100%" in text
    for name in ("fig07_stiction", "fig13_processing"):
        assert f"<a href='{name}.png'>PNG</a>" in text and f"<a href='{name}.svg'>SVG</a>" in text
    # the report's metric tables: a dash with a footnote, or a value above the trusted start
    tables = [t for t in re.findall(r"<table>.*?</table>", text, flags=re.S) if "peak of T at" in t]
    assert len(tables) == 6
    for table in tables:
        for row in re.findall(r"<tr>(.*?)</tr>", table, flags=re.S)[1:]:
            cells = re.findall(r"<td>(.*?)</td>", row)
            trusted_from, resonance = float(cells[1]), cells[2]
            assert resonance.startswith("&mdash;<sup>") or float(resonance) > trusted_from
        dashes = {int(n) for n in re.findall(r"&mdash;<sup>(\d+)</sup>", table)}
        if dashes:
            notes = re.match(r"\s*<ol class='notes'>(.*?)</ol>",
                             text[text.index(table) + len(table):], flags=re.S)
            assert len(re.findall("<li>", notes.group(1))) == max(dashes)


def test_study_cli_prints_json(tmp_path, capsys):
    """``qzs study FILE --json``: claims, per-case metrics with NaN as null beside a reason."""
    from qzs.cli import main

    path = tmp_path / "tiny.toml"
    path.write_text("[study]\nname = 'tiny'\nkind = 'transmissibility'\n"
                    "claims = ['no_pi_stops', 'stiction_low_frequency']\n"
                    "[[study.view]]\nfigure = 'tiny'\nfrequency_range = [0.0, 20.0]\n"
                    "[analysis]\nquick_fft_length = 2048\nquick_n_averages = 6\n"
                    "[[case]]\nlabel = 'no PI'\npi_kp = 0.0\npi_ki = 0.0\n"
                    "[[case]]\nlabel = 'PI'\npi_kp = 5.0\npi_ki = 2.0\n")
    out = tmp_path / "out"
    code = main(["study", str(path), "--quick", "--out", str(out), "--workers", "1", "--quiet",
                 "--json"])
    assert code == 0
    record = json.loads(capsys.readouterr().out)
    verdicts = {c["claim"]: c for c in record["claims"]}
    assert verdicts["stiction_low_frequency"]["verdict"] == "not decidable"
    assert verdicts["no_pi_stops"]["study"] == "tiny" and verdicts["no_pi_stops"]["evidence"]
    cases = record["studies"]["tiny"]["cases"]
    assert [c["case"] for c in cases] == ["no PI", "PI"]
    for entry in cases:
        for name, value in entry.items():
            if value is None and name in ("resonance_frequency", "isolation_onset"):
                assert entry[f"{name}_reason"]
    outputs = record["outputs"]
    assert outputs["report"] == str(out / "report.html")
    assert str(out / "tiny.png") in outputs["figures"] and str(out / "tiny.svg") in outputs["figures"]
    assert outputs["curves"] == [str(out / f"tiny_curves{suffix}") for suffix in (".nc", ".csv", ".mat")]
    for path in (outputs["report"], outputs["metrics_json"], outputs["metrics_csv"],
                 *outputs["figures"], *outputs["curves"]):
        assert (tmp_path / path).exists() or __import__("pathlib").Path(path).exists()


def test_study_physics_is_sensible(quick_paper):
    results, _, _ = quick_paper
    by_name = {r.study.name: r for r in results}
    fit = by_name["spring"].cases[0].extra["fit"]
    assert fit["intervals"]["plateau"][0] <= 60.84 <= fit["intervals"]["plateau"][1]
    for case in by_name["viscous"].cases:
        # above the stick-slip band the nonlinear curve follows the linearised model
        keep = (case.frequency > 6) & (case.frequency < 18)
        ratio = case.magnitude[keep] / case.linear["magnitude"][keep]
        assert np.all(np.abs(ratio - 1) < 0.1)


def test_lockstep_studies_match_the_one_case_path_to_the_last_bit(monkeypatch):
    """Cases sharing a chirp go through the batch kernel together; every curve, metric and
    statistic equals the one-case path's exactly (a processing case joins the same batch and
    brings the velocities). A case repeated in another study (the viscous study's Cv = 100
    N s/m is the stiction study's Fs = 10 N: both are Table 1 with the passive gains) is
    integrated once and analysed for each."""
    import dataclasses

    stiction = load_study("stiction")
    processing = load_study("processing")
    viscous = load_study("viscous")
    analysis = {"quick_fft_length": 2048, "quick_n_averages": 6}
    repeated = [case for case in viscous.cases if case["viscous_damping"] == 100.0]
    studies = [dataclasses.replace(stiction, analysis={**stiction.analysis, **analysis},
                                   cases=stiction.cases[::2]),
               dataclasses.replace(processing, analysis={**processing.analysis, **analysis},
                                   options={**processing.options, "n_averages": 6}),
               dataclasses.replace(viscous, analysis={**viscous.analysis, **analysis},
                                   cases=repeated)]
    import qzs.engine.batch

    batches = []
    original = qzs.engine.batch.simulate_batch

    def counted(cases, *args, **kwargs):
        batches.append(len(cases))
        return original(cases, *args, **kwargs)

    monkeypatch.setattr(qzs.engine.batch, "simulate_batch", counted)
    lockstep = run_studies(studies, quick=True, workers=2, progress=False, dt=1e-3)
    # two stiction cases and the processing case: one batch; the viscous case is Fs = 10 N
    assert batches == [3]
    assert [case["stiction_force"] for case in stiction.cases[::2]] == [2.0, 10.0]
    single = run_studies(studies, quick=True, workers=1, progress=False, lockstep=False,
                         dt=1e-3)
    assert batches == [3]

    def same(a, b):
        if isinstance(a, np.ndarray):
            return np.array_equal(a, b, equal_nan=True)
        if isinstance(a, float) and np.isnan(a):
            return isinstance(b, float) and np.isnan(b)
        return a == b

    compared = 0
    for study_a, study_b in zip(lockstep, single):
        for a, b in zip(study_a.cases, study_b.cases):
            for field in ("frequency", "magnitude", "coherence", "trusted"):
                assert same(getattr(a, field), getattr(b, field)), (a.label, field)
            for name in a.metrics:
                assert same(a.metrics[name], b.metrics[name]), (a.label, name)
                compared += 1
            for name in a.stats:
                if name != "steps_per_second":
                    assert same(a.stats[name], b.stats[name]), (a.label, name)
            for name in ("metrics", "magnitude"):
                if a.extra:
                    assert same(str(a.extra[name]), str(b.extra[name])), (a.label, name)
    assert compared > 20
    assert lockstep[1].cases[0].extra["magnitude"].size > 0
    assert same(lockstep[2].cases[0].magnitude, lockstep[0].cases[1].magnitude)


def test_the_step_is_chosen_for_the_tolerance_or_given_or_the_files(tmp_path, monkeypatch):
    """No ``dt``: one step for the batch, chosen for the tolerance and recorded with its
    estimate; ``dt`` given: used as given, nothing probed, over a file's; a file's
    ``[simulation] dt``: used as written; ``dt`` and a tolerance both: refused at once."""
    import qzs.engine.step_choice
    from qzs.engine.accuracy import SAFETY

    text = ("[study]\nname = 'tiny'\nkind = 'transmissibility'\n"
            "[analysis]\nquick_fft_length = 2048\nquick_n_averages = 6\n"
            "[[case]]\nlabel = 'Table 1'\n[[case]]\nlabel = 'Cv = 200'\nviscous_damping = 200.0\n")
    path = tmp_path / "tiny.toml"
    path.write_text(text)
    study = load_study(path)
    chosen = run_studies([study], quick=True, workers=1, progress=False)[0]
    step = chosen.step
    assert step["source"] == "chosen" and step["tolerance_db"] == 0.01 and not step["unmet"]
    assert 1e-4 < step["dt"] <= 1e-3 and 0 <= step["estimated_error_db"] * SAFETY <= 0.01
    assert [case.run["dt"] for case in chosen.cases] == [step["dt"]] * 2

    def refuse(*args, **kwargs):
        raise AssertionError("a step was chosen where one was given")

    monkeypatch.setattr(qzs.engine.step_choice, "choose", refuse)
    path.write_text(text + "[simulation]\ndt = 5e-4\n")
    from_file = run_studies([load_study(path)], quick=True, workers=1, progress=False)[0]
    assert from_file.step == {"dt": 5e-4, "source": "file"}
    assert [case.run["dt"] for case in from_file.cases] == [5e-4] * 2
    given = run_studies([load_study(path)], quick=True, workers=1, progress=False, dt=2.5e-4)[0]
    assert given.step == {"dt": 2.5e-4, "source": "given"}
    assert [case.run["dt"] for case in given.cases] == [2.5e-4] * 2
    with pytest.raises(ParameterError, match="not both"):
        run_studies([study], dt=1e-3, tolerance=0.01)
    with pytest.raises(ParameterError, match="`tolerance`"):
        run_studies([study], tolerance=-1.0)
    with pytest.warns(DeprecationWarning, match="use `tolerance`"), \
            pytest.raises(ParameterError, match="not both"):
        run_studies([study], dt=1e-3, tolerance_db=0.01)  # the deprecated name, one release


def test_a_batch_no_step_settles_runs_at_the_papers_step_and_says_so(tmp_path):
    """Every case on the stops (no PI): no step meets the tolerance for any; the batch runs
    at the paper's dt = 1e-4 s, and the record and the statement say why."""
    from qzs.workflows.paper.report_step import step_record

    path = tmp_path / "stops.toml"
    path.write_text("[study]\nname = 'stops'\nkind = 'transmissibility'\n"
                    "[analysis]\nquick_fft_length = 8192\nquick_n_averages = 6\n"
                    "[[case]]\nlabel = 'no PI'\npi_kp = 0.0\npi_ki = 0.0\n")
    result = run_studies([load_study(path)], quick=True, workers=1, progress=False)[0]
    assert result.step["source"] == "fallback" and result.step["dt"] == 1e-4
    assert result.step["unmet"] == ["no PI"] and "no step down to" in result.step["notes"][0]
    assert result.cases[0].run["dt"] == 1e-4
    statement = step_record([result])["statement"]
    assert "the paper's own: no step met 0.01 dB for any case" in statement
    assert "agrees" not in statement


def test_the_studies_run_a_spring_law_and_the_report_says_which(tmp_path):
    """``run_studies(..., spring=law)`` (``qzs paper --spring``, docs/model.md §3.1): every
    simulated case is the single run of that law (its transmissibility equal to a
    ``qzs.simulate`` of the same isolator, bit for bit), the spring study measures and fits
    that law as its kind (the true coefficients inside the fitted intervals), and the report's
    metrics.json, HTML and spring curves name the law."""
    import dataclasses

    import qzs
    from qzs.analysis.spectral import transmissibility as estimate
    from qzs.workflows.paper.cases import case_inputs
    from qzs.workflows.paper.studies import _study_cases

    law = qzs.PolynomialSpring(coefficients=(62.78, -100.0, 0.0, -5e4), center=-0.06)
    stiction = load_study("stiction")
    analysis = {"quick_fft_length": 2048, "quick_n_averages": 6}
    studies = [load_study("spring"),
               dataclasses.replace(stiction, analysis={**stiction.analysis, **analysis},
                                   cases=stiction.cases[1:3])]
    results = run_studies(studies, quick=True, workers=1, progress=False, dt=1e-3,
                          spring=law)
    assert all(r.spring == law for r in results)
    fit = results[0].cases[0].extra["law_fit"]
    assert fit.kind == "polynomial" and results[0].cases[0].label == "polynomial"
    for k, truth in enumerate(law.coefficients):
        low, high = fit.intervals[f"c{k}"]
        assert low <= truth <= high, (k, low, truth, high)
    assert results[0].cases[0].metrics["spring.c1"] == pytest.approx(-100.0, abs=30.0)
    task = _study_cases(studies[1], True, 1e-3, law)[0]
    isolator, controller, excitation, rate = case_inputs(task)
    assert isolator.spring == law
    run = qzs.simulate(excitation, isolator, controller, sample_rate=rate, dt=1e-3)
    case = results[1].cases[0]
    direct = estimate(run.base_acceleration, run.payload_acceleration, rate,
                      fft_length=task.analysis["fft_length"],
                      n_averages=task.analysis["n_averages"])
    band = (direct.frequency >= case.frequency[0]) & (direct.frequency <= case.frequency[-1])
    np.testing.assert_array_equal(case.magnitude, direct.magnitude[band])
    default = run_studies(studies[1:], quick=True, workers=1, progress=False, dt=1e-3)
    assert not np.array_equal(default[0].cases[0].magnitude, case.magnitude)
    write_paper_outputs(results, tmp_path, quick=True)
    document = json.loads((tmp_path / "metrics.json").read_text())
    assert document["spring"]["law"] == "polynomial"
    assert document["spring"]["coefficients"] == [[62.78, -100.0, 0.0, -5e4], "N/m^k"]
    import html as markup

    html = markup.unescape((tmp_path / "report.html").read_text())
    assert "polynomial spring" in html and "not the paper's MagSpring" in html
    import xarray as xr

    curves = xr.open_dataset(tmp_path / "spring_curves.nc")
    assert curves.attrs["spring_kind"] == "polynomial"
    # the file's labels name the law it holds, not the MagSpring's tanh
    assert "tanh" not in curves["fitted_force"].attrs["long_name"]
    assert "polynomial" in curves["fitted_force"].attrs["long_name"]
    assert "MagSpring" not in curves["displacement"].attrs["long_name"]
    np.testing.assert_allclose(curves["fitted_force"].values,
                               fit.law.force(curves["displacement"].values))


def test_the_report_of_the_default_spring_names_the_magspring(quick_paper):
    """Without --spring the report names the MagSpring's tanh, Table 1's numbers."""
    from qzs.workflows.paper.report_spring import spring_record, spring_statement

    results, _, folder = quick_paper
    assert json.loads((folder / "metrics.json").read_text())["spring"] == spring_record(results)
    assert spring_record(results) == {"law": "tanh", "plateau": [60.84, "N"],
                                      "shape": [78.10, "1/m"]}
    assert spring_statement(results).startswith("tanh spring (MagSpring)")
    assert "the paper's, the default" in spring_statement(results)


def test_an_explicit_tanh_spring_is_the_paper_s_magspring():
    """``run_studies(..., spring=TanhSpring())`` is the default: the spring study fits the
    MagSpring's tanh (``spring_force``, ``spring_shape``) under the MagSpring's label."""
    import qzs

    study = load_study("spring")
    explicit = run_studies([study], quick=True, workers=1, progress=False,
                           spring=qzs.TanhSpring())
    default = run_studies([study], quick=True, workers=1, progress=False)
    assert explicit[0].cases[0].label == default[0].cases[0].label == "MagSpring"
    assert explicit[0].cases[0].metrics == default[0].cases[0].metrics
    assert set(default[0].cases[0].metrics) == {"spring_force", "spring_shape"}


def test_a_tanh_other_than_the_paper_s_is_run_or_refused_never_swapped_for_the_magspring():
    """A tanh law with other numbers than Table 1's is either the law every case runs (the
    report states and records it, the spring study measures it) or refused naming `spring`;
    never silently replaced by the paper's MagSpring."""
    import qzs
    from qzs.workflows.paper.report_spring import spring_record, spring_statement

    law = qzs.TanhSpring(plateau=40.0, shape=50.0)
    try:
        results = run_studies([load_study("spring")], quick=True, workers=1, progress=False,
                              spring=law)
    except ParameterError as error:
        assert "spring" in str(error)
        return
    assert spring_record(results) == {"law": "tanh", "plateau": [40.0, "N"],
                                      "shape": [50.0, "1/m"]}
    assert "the paper's, the default" not in spring_statement(results)
    fitted = results[0].cases[0].metrics
    assert fitted.get("spring_force", fitted.get("spring.plateau")) == pytest.approx(40.0,
                                                                                   rel=0.05)


def test_a_plan_carries_each_chosen_step_in_new_cases_and_mutates_none(monkeypatch):
    """plan_studies resolves once: the step the (here stubbed) batch choice returns is in
    every simulated case of the plan, made by dataclasses.replace, while the cases it was
    chosen for keep dt None; the spring study's case has no step; the record says which
    case the choice did not meet. The cases are frozen: nothing can write a step into them."""
    import dataclasses
    import types

    import qzs.engine.step_choice as step_choice
    from qzs.engine.step_choice import StepRequest
    from qzs.workflows.paper.studies import StudyCase, _choose_steps, _study_cases, plan_studies

    seen = {}

    def choose(request, probe, **options):
        seen["labels"] = probe.labels
        cases = probe.cases
        return types.SimpleNamespace(dt=2.5e-4, met=True, tolerance=request.tolerance,
                                     case_errors=[0.01 * (c + 1) for c in range(len(cases))],
                                     unmet=(1,), reference_dt=1.25e-4, probe_duration=5.0,
                                     notes=("probed",), cached=False)

    monkeypatch.setattr(step_choice, "choose", choose)
    stiction, spring = load_study("stiction"), load_study("spring")
    per_study = [_study_cases(stiction, True), _study_cases(spring, True)]
    assert all(case.dt is None for case in per_study[0])
    cases, steps = _choose_steps(per_study, StepRequest(tolerance=0.05), 1, False)
    assert all(case.dt is None for case in per_study[0])  # not written into
    assert [case.dt for case in cases[0]] == [2.5e-4] * len(stiction.cases)
    assert cases[0][0] == dataclasses.replace(per_study[0][0], dt=2.5e-4)
    assert cases[1] == per_study[1] and cases[1][0].dt is None and steps[1] == {}
    assert seen["labels"] == [case.label for case in per_study[0]]
    assert steps[0]["dt"] == 2.5e-4 and steps[0]["source"] == "chosen"
    assert steps[0]["unmet"] == [per_study[0][1].label]
    assert steps[0]["estimated_error_db"] == max(0.01 * (c + 1) for c in range(len(cases[0]))
                                                 if c != 1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        cases[0][0].dt = 1e-4
    plan = plan_studies([stiction, spring], quick=True, workers=1, progress=False, dt=1e-3)
    assert isinstance(plan.cases[0][0], StudyCase)
    assert {(case.dt, case.step_source) for case in plan.cases[0]} == {(1e-3, "given")}
    assert plan.steps[0] == {"dt": 1e-3, "source": "given"}
