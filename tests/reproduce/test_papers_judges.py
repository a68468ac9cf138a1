"""The Chan, Karamat and Park reproductions' claim structure and their Park judges and paper
figures on synthetic per-seed tables whose answer is known (``simulator/reproduce/judged.py``,
``seed_plots.py``, the paper modules)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from simulator.reproduce import chan, judged, karamat2015, park2019, seed_plots
from simulator.reproduce.evidence import verdict_word

PAPERS = (chan.PAPER, karamat2015.PAPER, park2019.PAPER)
SEEDS = pd.Index(range(1, 7), name="seed")


@pytest.mark.parametrize("paper", PAPERS, ids=lambda p: p.key)
def test_every_sweep_variant_names_a_default_claim_and_every_untestable_claim_says_why(paper):
    keys = {c.key: c for c in paper.claims}
    for claim in paper.claims:
        if claim.variant_of:
            default = keys[claim.variant_of]
            assert not default.variant_of and default.kind == claim.kind
            assert any("(the default:" in c for c in default.conditions)
        if claim.untestable:
            assert claim.judge is None and claim.kind == "paper" and len(claim.untestable) > 30
    assert sum(c.kind == "paper" and not c.variant_of for c in paper.claims) >= 10


def test_worst_keeps_the_worst_words_evidence_and_every_per_seed_list():
    good = judged.one_sample([1.0] * 6, name="x", threshold=2.0, better="lower")
    bad = judged.one_sample([3.0] * 6, name="x", threshold=2.0, better="lower")
    both = judged.worst([good, bad])
    assert (good.status, bad.status, both.status) == ("shown", "not shown", "not shown")
    assert both.evidence is bad.evidence and both.compared == ("x (2)",)
    assert both.per_seed == {"x": [1.0] * 6, "x (2)": [3.0] * 6}
    magnitude = both.magnitude.holds(both.evidence) if both.magnitude else None
    assert verdict_word(both.evidence, magnitude_ok=magnitude) == both.status


@pytest.mark.parametrize("ratio, status", [(0.33, "shown"), (0.8, "partly"), (1.2, "not shown")])
def test_park_tunnel_ratio_words(ratio, status):
    """Fig. 18: 1.91 vs 5.74 m, a ratio of 0.33 +- 0.15."""
    table = pd.DataFrame({"dr3d_ekf.exit_horizontal_m": [ratio * 6.0] * 6,
                          "dr2d_odo_ekf.exit_horizontal_m": [6.0] * 6}, index=SEEDS)
    claim = next(c for c in park2019.PAPER.claims if c.key == "fig18_tunnel_beats_2d")
    verdict = claim.judge({"curved_tunnel": table})
    assert verdict.status == status
    assert verdict.evidence.effect == pytest.approx(ratio)


def test_park_height_contrast_needs_the_ins_four_times_worse():
    table = pd.DataFrame({"dr3d_ekf.height_change_error_m": [1.0] * 6,
                          "ins_odo_ekf.height_change_error_m": [2.0] * 6}, index=SEEDS)
    assert park2019.judge_height_contrast({"garage": table}).status == "partly"
    table["ins_odo_ekf.height_change_error_m"] = 20.0
    assert park2019.judge_height_contrast({"garage": table}).status == "shown"
    table["ins_odo_ekf.height_change_error_m"] = 0.5
    assert park2019.judge_height_contrast({"garage": table}).status == "not shown"


def test_park_ablation_pairs_across_experiments_of_the_same_datasets():
    garage = pd.DataFrame({"dr3d_ekf.rms_tilt_deg": [0.5] * 6}, index=SEEDS)
    ablation = pd.DataFrame({"dr3d_no_adaptation.rms_tilt_deg": [0.9] * 6}, index=SEEDS)
    claim = next(c for c in park2019.PAPER.claims if c.key == "adaptation_improves_attitude")
    verdict = claim.judge({"garage": garage, "garage_ablation": ablation})
    assert verdict.status == "shown"
    assert verdict.per_seed == {"dr3d_ekf": [0.5] * 6, "dr3d_no_adaptation": [0.9] * 6}


def _histories(prefix: str, seconds: range) -> dict[str, list[float]]:
    return {f"{prefix}{s:02d}": [float(s)] * 6 for s in seconds}


def test_paper_figures_draw_from_the_per_seed_tables():
    """Each paper's figures function draws its layouts from per-seed tables (the figure count
    follows from the experiments present)."""
    partial_cols = {"w0.satellites": [0.0] * 6, **{f"{label}.w0.t{s:02d}": [float(s)] * 6
                                                   for label in (chan.NHC, chan.NO_NHC)
                                                   for s in range(0, 60, 5)},
                    f"{chan.NHC}.nees_position": [3.0] * 6}
    tables = {"complete_outages": pd.DataFrame(partial_cols, index=SEEDS)}
    captions = [c for c, _ in chan.figures({}, tables)]
    assert captions[0].startswith("Figure 4 layout") and captions[-1].startswith("Position NEES")
    park = pd.DataFrame({**_histories("dr3d_ekf.h", range(0, 60, 10)),
                         "dr3d_ekf.height_change_error_m": [1.0] * 6,
                         "ins_odo_ekf.height_change_error_m": [9.0] * 6,
                         "dr3d_ekf.exit_horizontal_m": [5.0] * 6,
                         "dr2d_odo_ekf.exit_horizontal_m": [6.0] * 6}, index=SEEDS)
    captions = [c for c, _ in park2019.figures({}, {"garage": park})]
    assert [c[:7] for c in captions] == ["Figs. 1", "Fig. 19"]
    karamat = pd.DataFrame({**_histories("tight.gyro_bias_error_t", range(0, 600, 30)),
                            **{f"{v}.sats{c}.mean_max_h_m": [float(c)] * 6
                               for v in ("tight", "simplified") for c in karamat2015.COUNTS},
                            **{col: [1.0] * 6 for block in karamat2015.TABLE2.values()
                               for col, _, _ in block.values()}}, index=SEEDS)
    captions = [c for c, _ in karamat2015.figures({}, {"partial_outages": karamat})]
    assert [c.split(" layout")[0] for c in captions] == ["Figure 8", "Figure 13", "Table 2"]
    assert np.isfinite(karamat2015.seed_maxima(karamat, "tight", 0)).all()


def test_nees_history_figure_draws_one_panel_per_history():
    history = pd.DataFrame({"t": np.arange(10.0), "gnss_outage": [0.0] * 5 + [1.0] * 5,
                            "tight.nees_position": np.linspace(1.0, 9.0, 10),
                            "tight.nees_dof": 3.0})
    ((caption, fig),) = seed_plots.nees_history_figure({"a": history, "b": history})
    assert caption.startswith("Position NEES against time") and len(fig.axes) == 2
    assert seed_plots.nees_history_figure({}) == []


def _karamat_check(key: str):
    return next(c for c in karamat2015.PAPER.claims if c.key == key)


def test_karamat_bias_observability_check_tells_a_tracking_estimate_from_a_stuck_one():
    """The check's evidence is per seed: an estimate within 2 mg of truths of 10-60 mg is
    observed (6/6 seeds, sign test p = 1/64), one stuck near zero whatever the truth is not."""
    assert _karamat_check("accel_bias_x_observable").kind == "check"
    true = np.array([10.0, -25.0, 40.0, 60.0, -15.0, 30.0])
    for estimate, status in ((true + 2.0, "shown"), (np.full(6, 0.4), "not shown")):
        table = pd.DataFrame({"tight.accel_bias_x_est_mg": estimate,
                              "true.accel_bias_x_mg": true}, index=SEEDS)
        verdict = _karamat_check("accel_bias_x_observable").judge({"partial_outages": table})
        assert verdict.status == status
        assert verdict.per_seed["|estimate - truth|"] == pytest.approx(
            list(np.abs(estimate - true)))


@pytest.mark.parametrize("variant", ["no_accel_bias", "no_tilt", "no_speed_error",
                                     "no_accel_update", "simplified"])
def test_karamat_ablation_check_pairs_the_variant_with_the_full_model_per_seed(variant):
    """A variant 40 % worse on every seed is a loss (ratio 1 / 1.4); one equal to the full model
    is not (every seed a tie)."""
    full = np.array([10.0, 3.0, 8.0, 12.0, 6.0, 9.0])
    for factor, status in ((1.4, "shown"), (1.0, "not shown")):
        columns = {}
        for label, values in (("tight", full), (variant, factor * full)):
            for c in karamat2015.COUNTS:
                columns[f"{label}.sats{c}.mean_max_h_m"] = values
        table = pd.DataFrame(columns, index=SEEDS)
        verdict = _karamat_check(f"ablation_{variant}").judge({"partial_outages": table})
        assert verdict.status == status
        assert verdict.evidence.effect == pytest.approx(1.0 / factor)
        assert verdict.per_seed[variant] == pytest.approx(list(factor * full))
