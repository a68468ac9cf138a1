"""The verdict logic of ``simulator.reproduce.measures`` and the paper modules' judges on
synthetic per-seed figures: a claim is judged shown, partly or not shown as the criterion says."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simulator.reproduce import cho2006, park2019, tan2008
from simulator.reproduce import measures as m
from simulator.reproduce.paper import SCENARIO_DIR
from simulator.reproduce.papers import PAPERS, load_paper, paper_keys
from simulator.reproduce.runner import judge


@pytest.mark.parametrize("fraction, n, need", [(0.9, 10, 9), (0.8, 10, 8), (0.9, 3, 3),
                                               (0.8, 3, 3), (1.0, 7, 7), (0.5, 4, 2)])
def test_needed_count_scales_the_criterion_to_the_seeds_run(fraction, n, need):
    assert m.needed_count(fraction, n) == need


@pytest.mark.parametrize("successes, status", [(10, "shown"), (9, "shown"), (8, "not shown"),
                                               (5, "not shown"), (0, "not shown")])
def test_count_verdict_is_the_sign_test_on_the_seeds_that_meet_it(successes, status):
    """9 of 10: p = 11/1024 < 0.05; 8 of 10: p = 56/1024 > 0.05 (the count criterion of old
    is no longer the rule)."""
    verdict = m.count_verdict(successes, 10, 0.9, "measured", "converges", "why not")
    assert verdict.status == status
    assert verdict.measured == "measured"
    assert f"{successes}/10" in verdict.reason
    assert ("why not" in verdict.reason) == (status != "shown")
    assert verdict.evidence.wins == successes and verdict.evidence.n == 10


def test_count_verdict_without_seeds_is_not_shown():
    assert m.count_verdict(0, 0, 0.9, "no figure", "converges").status == "not shown"


@pytest.mark.parametrize("values, status", [([0.5, 0.4, 0.8, 0.6, 0.45], "shown"),
                                            ([0.1, 0.2, 0.25, 0.1, 0.2], "partly"),
                                            ([0.5, 0.4, 0.8], "not shown"),  # 3 seeds: p 1/8
                                            ([-0.1, 0.0, -0.3, 0.1, 0.2], "not shown"),
                                            ([np.nan, np.nan], "not shown")])
def test_median_verdict_above_a_bound(values, status):
    assert m.median_verdict(values, 0.3, "above", 0.0, "x", "cut").status == status


def test_median_verdict_below_a_bound():
    assert m.median_verdict([0.9, 1.0, 1.05, 0.8, 0.95], 1.1, "below", 1.1, "x",
                            "ratio").status == "shown"
    assert m.median_verdict([1.2, 1.3], 1.1, "below", 1.1, "x", "ratio").status == "not shown"


def test_paired_wins_compare_seeds_with_both_figures_and_count_the_others():
    a = np.array([1.0, 5.0, np.nan, 2.0])
    b = np.array([2.0, 4.0, 1.0, np.nan])
    assert m.paired_wins(a, b) == (1, 2)
    assert m.missing_count(a, b) == 2
    assert m.win_rate_text(1, 2, "a") == "a better in 1/2 seeds (50 %)"
    assert m.win_rate_text(1, 2, "a", 2) == "a better in 1/2 seeds (50 %), 2 without a figure"
    # the verdict counts the two seeds without both figures as seeds where a did not win
    verdict = m.paired_verdict(a, b, ("a", "b"), 0.5, "m", "a beats b")
    assert verdict.status == "not shown" and "direction held in 1 of 4 seeds" in verdict.reason
    assert "2 without a value" in verdict.reason
    assert verdict.per_seed == {"a": [1.0, 5.0, None, 2.0], "b": [2.0, 4.0, 1.0, None]}


def test_spread_text_gives_median_iqr_and_range_and_counts_missing_seeds():
    text = m.spread_text([1.0, 2.0, 3.0, 4.0, 5.0], "m")
    assert text == "median 3 m (IQR 2-4, range 1-5; 5 seeds)"
    text = m.spread_text([1.0, np.nan, 3.0, np.nan, 2.0], "m")
    assert text == "median 2 m (IQR 1.5-2.5, range 1-3; 3 seeds, 2 without a figure)"
    assert m.spread_text([]) == "no figure (every seed failed)"
    assert m.spread_text([np.nan, np.nan]) == "no figure (none of 2 seeds has one)"


def test_column_keeps_seeds_without_a_figure_in_seed_order():
    table = pd.DataFrame({"x.end_m": [1.0, np.nan, 3.0], "y.end_m": [np.nan, 2.0, 1.0]},
                         index=[1, 2, 3])
    x, y = m.column(table, "x.end_m"), m.column(table, "y.end_m")
    np.testing.assert_array_equal(x, [1.0, np.nan, 3.0])
    assert m.paired_wins(y, x) == (1, 1)  # seed 3 only: paired, not shifted
    assert m.least_count({"x": x}, lambda v: v < 5.0) == (2, 3)  # a missing seed fails
    verdict = m.median_verdict(x, 1.5, "above", 0.0, "x", "end")
    assert verdict.status == "not shown" and "1 without a value" in verdict.reason


def test_windows_from_the_events_table():
    events = pd.DataFrame({"t_start": [10.0, 50.0, 30.0], "t_end": [20.0, 110.0, 35.0],
                           "kind": ["gnss_outage", "gnss_outage", "zone"],
                           "detail": ["", "", "tunnel"]})
    assert m.longest_outage(events) == (50.0, 110.0)
    t = np.array([5.0, 10.0, 19.9, 20.0, 60.0, 110.0])
    np.testing.assert_array_equal(m.inside_windows(t, m.outages(events)),
                                  [False, True, True, False, True, False])


def test_cho_and_tan_judges_follow_the_rule_on_synthetic_seeds():
    """Ten seeds: the SPKF converges in 9 at -140 deg (p = 11/1024: shown), the EKF stays above
    3 deg in 8 (p = 0.055: not shown); Tan's constraints win 10 of 10 (shown), the magnetometer
    5 of 10 (not shown)."""
    seeds = pd.Index(range(1, 11), name="seed")
    s2 = pd.DataFrame({"spkf_m140.heading_rms_deg": [0.5] * 9 + [10.0],
                       "ekf_m140.heading_rms_deg": [20.0] * 8 + [1.0] * 2}, index=seeds)
    verdicts = judge(cho2006.PAPER, {"situation2": s2})
    assert verdicts["situation2_spkf_converges_140"].status == "shown"
    assert verdicts["situation2_ekf_diverges_140"].status == "not shown"
    assert verdicts["situation2_spkf_converges_140"].evidence.wins == 9
    outage = pd.DataFrame({f"{label}.{figure}": np.arange(10.0) + offset
                           for label, offset in (("free", 100.0), ("constraints", 10.0),
                                                 ("full", 10.0), ("closed", 0.0),
                                                 ("no_standstill", 5.0))
                           for figure in ("end_horizontal_m", "max_horizontal_m",
                                          "standstill_heading_deg")}, index=seeds)
    outage["full.end_horizontal_m"] = outage["constraints.end_horizontal_m"] + [-1.0, 1.0] * 5
    outage["outage.distance_m"] = 700.0
    verdicts = judge(tan2008.PAPER, {"outage": outage})
    assert verdicts["constraints_reduce_outage_error"].status == "shown"
    assert verdicts["magnetometer_reduces_outage_error"].status == "not shown"
    assert verdicts["small_error_70_s"].evidence is None
    assert "median 700 m (IQR 700-700" in verdicts["small_error_70_s"].measured


def test_park_flat_ratio_judge():
    """Six seeds: exit ratios near 1 but the max ratio 0.5 (an advantage left): not shown;
    both within 0.3 of 1 in every seed: shown."""
    seeds = pd.Index(range(1, 7), name="seed")
    flat = pd.DataFrame({"dr3d_ekf.exit_horizontal_m": [10.0] * 6,
                         "dr3d_ekf.max_horizontal_m": [10.0] * 6,
                         "dr2d_odo_ekf.exit_horizontal_m": [9.0, 11.0, 10.0, 9.5, 10.5, 10.0],
                         "dr2d_odo_ekf.max_horizontal_m": [20.0] * 6}, index=seeds)
    claim = next(c for c in park2019.PAPER.claims if c.key == "flat_no_advantage_2d")
    assert claim.kind == "check"
    assert claim.judge({"flat_garage": flat}).status == "not shown"
    flat["dr2d_odo_ekf.max_horizontal_m"] = 11.0
    assert claim.judge({"flat_garage": flat}).status == "shown"


def test_a_judge_without_its_figures_is_not_shown_with_the_reason():
    verdicts = judge(tan2008.PAPER, {"outage": pd.DataFrame(index=pd.Index([], name="seed"))})
    assert all(v.status == "not shown" for v in verdicts.values())
    testable = [c.key for c in tan2008.PAPER.claims if not c.untestable]
    # either the judge could not read its figures or its evidence has no seed
    assert all("could not be judged" in verdicts[key].reason
               or verdicts[key].evidence.n == 0 for key in testable)
    # the untestable claim's figure says it has none
    assert "no figure" in verdicts["small_error_70_s"].measured


def test_every_registered_paper_loads_with_unique_keys_and_module_level_measures():
    assert set(paper_keys()) <= set(PAPERS)
    assert {"cho2006", "tan2008", "park2019"} <= set(paper_keys())
    for key in paper_keys():
        paper = load_paper(key)
        assert paper.key == key
        assert len({e.key for e in paper.experiments}) == len(paper.experiments)
        assert len({c.key for c in paper.claims}) == len(paper.claims)
        for e in paper.experiments:
            # picklable by reference: a module-level function
            assert e.measure.__qualname__ == e.measure.__name__
            assert (SCENARIO_DIR / e.scenario).is_file(), e.scenario


@pytest.mark.parametrize("key", paper_keys())
def test_quick_runs_the_claims_that_are_no_variant_and_only_the_experiments_they_read(key):
    """``--quick`` (``Paper.quick``): every claim but the variants and the ``full_only``
    checks, every experiment a kept claim's judge reads, and no other, each with its
    ``quick_entries`` (all entries when it names none); every experiment of the full paper is
    read by a claim. (That the kept claims are judged from the entries left is asserted on the
    quick run itself: tests/reproduce/test_reproduce_cli.py.)"""
    paper = load_paper(key)
    quick = paper.quick()
    assert [c.key for c in quick.claims] == [c.key for c in paper.claims
                                            if not c.variant_of and not c.full_only]
    read = {e.key for c in quick.claims if c.judge is not None for e in paper.read_by(c)}
    assert [e.key for e in quick.experiments] == [e.key for e in paper.experiments
                                                 if e.key in read]
    full = {e.key: e for e in paper.experiments}
    for e in quick.experiments:
        kept = full[e.key].quick_entries or tuple(full[e.key].entries)
        assert list(e.entries) == list(kept) and set(kept) <= set(full[e.key].entries)
    assert {e.key for c in paper.claims if c.judge is not None for e in paper.read_by(c)} == \
        {e.key for e in paper.experiments}


def test_a_judge_is_given_only_the_experiments_it_declares():
    """A claim reading an experiment it does not name cannot be judged (the mapping --quick
    relies on is checked on every run); one without ``experiments`` reads them all."""
    from simulator.reproduce.paper import Claim, Experiment, Paper

    def read_b(tables):
        return m.count_verdict(int(tables["b"]["x"].sum()), 3, 0.9, "measured", "x")

    experiments = tuple(Experiment(k, "quickstart.yaml", {}, measure=len) for k in ("a", "b"))
    paper = Paper("p", "t", "c", experiments, (
        Claim("names_a", "t", "f", (), read_b, experiments=("a",)),
        Claim("names_b", "t", "f", (), read_b, experiments=("b",)),
        Claim("names_none", "t", "f", (), read_b)))
    table = pd.DataFrame({"x": [1, 1, 1]}, index=pd.Index([1, 2, 3], name="seed"))
    verdicts = judge(paper, {"a": table, "b": table})
    assert "could not be judged: KeyError" in verdicts["names_a"].reason
    assert verdicts["names_b"].evidence.wins == verdicts["names_none"].evidence.wins == 3
    with pytest.raises(ValueError, match="no experiment c"):
        Paper("p", "t", "c", experiments, (Claim("names_c", "t", "f", (), read_b,
                                                 experiments=("c",)),))


def test_a_claim_pairing_two_experiments_is_judged_on_the_seeds_both_have():
    """The second stage may run one experiment on further seeds: a claim pairing its figures
    with another experiment's is judged on their common seeds (it failed on 20 against 10)."""
    from simulator.reproduce.paper import Claim, Experiment, Paper

    def a_below_b(tables):
        return m.paired_judgement({"a": tables["long"]["x"].to_numpy(),
                                   "b": tables["short"]["x"].to_numpy()}, "a", "b",
                                  better="lower", kind="difference", unit="m", what="a lower")

    experiments = tuple(Experiment(k, "quickstart.yaml", {}, measure=len)
                        for k in ("long", "short"))
    paper = Paper("p", "t", "c", experiments, (
        Claim("pairs", "t", "f", (), a_below_b, experiments=("long", "short")),))
    long = pd.DataFrame({"x": [0.0] * 6}, index=pd.Index(range(1, 7), name="seed"))
    short = pd.DataFrame({"x": [1.0] * 3}, index=pd.Index([1, 2, 3], name="seed"))
    verdict = judge(paper, {"long": long, "short": short})["pairs"]
    assert verdict.evidence is not None, verdict.reason
    assert (verdict.evidence.n, verdict.evidence.wins) == (3, 3)


def test_the_experiments_of_a_claim_at_its_edge_are_run_on_further_seeds():
    from simulator.reproduce.evidence import one_sample_evidence
    from simulator.reproduce.paper import Claim, Experiment, Paper, Verdict
    from simulator.reproduce.runner import edge_experiments

    def experiment(key):
        return Experiment(key, "quickstart.yaml", {"a": {"name": "dead_reckoning"}},
                          measure=print)

    def verdict(wins):  # ten seeds, ``wins`` of them below the threshold
        values = [0.0] * wins + [2.0] * (10 - wins)
        evidence = one_sample_evidence(values, threshold=1.0, better="lower")
        word = "shown" if evidence.significant else "not shown"
        return Verdict(word, "", "", evidence, {"values": values})

    claims = tuple(Claim(f"c{i}", "", "", (), judge=len, experiments=(f"e{i}",))
                   for i in range(4))
    paper = Paper("p", "", "", tuple(experiment(f"e{i}") for i in range(4)), claims)
    # 9/10 (p 0.011) is shown, 8/10 (p 0.055) and 7/10 (p 0.17) sit at the edge, 6/10 (p 0.38)
    # is not shown whatever a few more seeds say
    verdicts = {"c0": verdict(9), "c1": verdict(8), "c2": verdict(7), "c3": verdict(6)}
    assert edge_experiments(paper, verdicts) == {"e1", "e2"}
    assert edge_experiments(paper, {"c0": verdicts["c0"]}) == set()


def _measured(experiment, seed, overrides, work, with_history=False):
    """Stands in for a seed's run: experiment "e0" below its threshold on every seed, "e1" on
    the even seeds only."""
    below = experiment.key == "e0" or seed % 2 == 0
    return {"value": 0.0 if below else 2.0}, None


def _judge_values(tables):
    from simulator.reproduce.evidence import one_sample_evidence
    from simulator.reproduce.paper import Verdict
    from simulator.reproduce.runner import ruled

    (table,) = tables.values()
    values = table["value"].tolist()
    evidence = one_sample_evidence(values, threshold=1.0, better="lower")
    return ruled(Verdict("not shown", "", "", evidence, {"values": values}))


def test_a_full_run_runs_the_edge_claims_experiments_again_on_further_seeds(tmp_path,
                                                                            monkeypatch):
    from simulator.reproduce import runner
    from simulator.reproduce.paper import Claim, Experiment, Paper
    from tests.experiment_cache import in_this_process

    paper = Paper("fake", "A fake paper", "", tuple(
        Experiment(k, "quickstart.yaml", {"a": {"name": "dead_reckoning"}}, measure=print)
        for k in ("e0", "e1")), tuple(
        Claim(f"c{k}", "below 1", "Table 1", (), judge=_judge_values, experiments=(k,))
        for k in ("e0", "e1")))

    monkeypatch.setattr(runner, "load_paper", lambda key: paper)
    monkeypatch.setattr(runner, "measure_seed", _measured)
    monkeypatch.setattr(runner, "open_executor", in_this_process)
    # three seeds: e0 below on 3 of 3 (p 0.125, at the edge: three more seeds), e1 on 1 of 3
    (result,) = runner.reproduce(["fake"], 3, False, tmp_path / "out", 1)
    assert list(result.experiments["e0"].table.index) == [1, 2, 3, 4, 5, 6]
    assert list(result.experiments["e1"].table.index) == [1, 2, 3]
    assert result.verdicts["ce0"].status == "shown"  # 6 of 6: p = 1/64
    assert result.verdicts["ce0"].evidence.n == 6
    # --quick has no second stage
    (quick,) = runner.reproduce(["fake"], 3, True, tmp_path / "quick", 1)
    assert list(quick.experiments["e0"].table.index) == [1, 2, 3]
