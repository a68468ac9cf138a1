"""The scenario reference and the JSON Schema are made from the schema itself: the committed
docs/scenario-reference.md is what the generator gives, every shipped scenario validates
against the JSON Schema (jsonschema, an independent validator), and unknown keys are refused."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
import yaml

from simulator.cli import main
from simulator.scenario.reference import json_schema, reference_markdown

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = sorted((REPO / "scenarios").glob("*.yaml"))


def test_committed_reference_is_the_generated_one():
    committed = (REPO / "docs" / "scenario-reference.md").read_text(encoding="utf-8")
    assert committed == reference_markdown(), (
        "docs/scenario-reference.md drifted from the schema: regenerate it with "
        "`python -m simulator.scenario.reference > docs/scenario-reference.md`")
    undocumented = [line for line in committed.splitlines() if line.endswith("|  |")]
    assert undocumented == [], "keys without a doc= string in the schema"


def _yaml(path: Path) -> dict:
    # as an editor sees the text: YAML timestamps are strings there
    return json.loads(json.dumps(yaml.safe_load(path.read_text()), default=str))


@pytest.fixture(scope="module")
def validator():
    schema = json_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.name for p in SCENARIOS])
def test_every_shipped_scenario_validates(validator, path):
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(_yaml(path))]
    assert errors == []


@pytest.mark.parametrize("where", [(), ("sensors", "imu"), ("start",)])
def test_an_unknown_key_is_refused(validator, where):
    data = _yaml(REPO / "scenarios" / "quickstart.yaml")
    block = data
    for key in where:
        block = block[key]
    block["bogus_key"] = 1
    assert not validator.is_valid(data)


def test_a_wrong_segment_and_fault_kind_are_refused(validator):
    data = _yaml(REPO / "scenarios" / "quickstart.yaml")
    data["trajectory"]["segments"].append({"teleport": {"length": 3}})
    assert not validator.is_valid(data)
    data = _yaml(REPO / "scenarios" / "quickstart.yaml")
    data["faults"] = [{"kind": "gnss_outage", "start": 3, "duration": "5 s"}]
    assert validator.is_valid(data)
    data["faults"][0]["kind"] = "meteor_strike"
    assert not validator.is_valid(data)


def test_schema_and_presets_commands(capsys):
    assert main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out) == json_schema()
    assert main(["presets"]) == 0
    out = capsys.readouterr().out
    assert "bosch-smi130" in out and "abs-wheel-speed" in out and "automotive" in out


@pytest.mark.parametrize("command", [None, "score", "generate", "estimate", "campaign", "run"])
def test_help_points_to_docs_not_to_spec(capsys, command):
    with pytest.raises(SystemExit):
        main([command, "--help"] if command else ["--help"])
    text = capsys.readouterr().out
    assert "SPEC" not in text
    if command in (None, "score", "generate", "estimate"):
        assert "docs/" in text


def test_faults_page_lists_every_kind_and_readme_shows_the_garage_plots():
    from simulator.faults import FAULT_REGISTRY

    faults = (REPO / "docs" / "faults.md").read_text(encoding="utf-8")
    assert all(f"| `{kind}` | {fk.doc} |" in faults for kind, fk in FAULT_REGISTRY.items())
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    for png in ("parking_garage_altitude.png", "parking_garage_outage_zoom.png"):
        assert f"(docs/images/{png})" in readme and (REPO / "docs" / "images" / png).is_file()
    assert "SPEC" not in readme
