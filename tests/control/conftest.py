import json

import pytest


@pytest.fixture(scope="session")
def paper_model_doc():
    """The model bank as 'hwpts reproduce --quick' identifies it (method 'paper'), as a model document."""
    from hwpts.commands.control import identify_model_bank
    from hwpts.io.models import model_to_dict

    model, r_hat, ts = identify_model_bank(seed=0, quick=True)
    return model_to_dict(model), r_hat, ts


@pytest.fixture(scope="session")
def paper_model_file(tmp_path_factory, paper_model_doc):
    path = tmp_path_factory.mktemp("model") / "paper.json"
    path.write_text(json.dumps(paper_model_doc[0]))
    return path


@pytest.fixture(scope="session")
def full_model_doc():
    """The model bank as 'hwpts control run' identifies it without --model (the full identification run)."""
    from hwpts.commands.control import identify_model_bank
    from hwpts.io.models import model_to_dict

    model, r_hat, ts = identify_model_bank(seed=0)
    return model_to_dict(model), r_hat, ts
