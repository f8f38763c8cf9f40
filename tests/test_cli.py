import re

import pytest

from qrrt_circuits.cli import main


@pytest.mark.parametrize("backend", ["aer", "statevector"])
def test_search_command(capsys, backend):
    assert main(["search", "--qubits", "6", "--marked", "3", "--shots", "500",
                 "--backend", backend, "--seed", "1"]) == 0
    out = capsys.readouterr().out
    rate = float(re.search(r"success rate\s+([0-9.]+)", out).group(1))
    theory = float(re.search(r"sin\^2\(\(2k\+1\)th\)\s+([0-9.]+)", out).group(1))
    assert abs(rate - theory) < 0.05
    assert "classical lookup" in out


def test_search_command_rejects_bad_input(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["search", "--qubits", "4", "--marked", "17"])
    assert exc.value.code == 2
    assert "--marked must be in [0, 2**qubits = 16]" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["search", "--shots", "0"])
