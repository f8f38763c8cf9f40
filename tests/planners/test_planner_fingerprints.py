"""Plans do not change: every planner's tree, counters and history for fixed seeds hash to the
reference values (tests/planner_fingerprints.py prints the table; regenerate it only for a change
meant to alter results, and say so). The quantum planners' references predate every performance
change; the classical planners' are those of their sequential extension-sample streams."""

from __future__ import annotations

import pytest
from planner_fingerprints import CASES, fingerprint, run_case

REFERENCE = {
    'rrt-clutter-0': 'e52a4a27aeddbcd79ffd9c10',
    'rrt-clutter-1': 'abd77b23e843987959982e8e',
    'rrt-clutter-2': 'ebed6e5faeb6e83d9d5b938a',
    'rrt-clutter-3': 'fce034dc5ec5141fc126615b',
    'rrt-clutter-4': 'f54f7f71a519b6bd9dac16b4',
    'rrt-clutter-5': '43d055de65559228cd3d01ba',
    'rrt-calls-0-1': '4b5322561cd90ea94b6173fc',
    'rrt-calls-1-37': '16b386278e1ff7c65e89b531',
    'rrt-calls-2-150': '49fb3349440e4f6b42522a1d',
    'rrt-calls-3-401': '8d3d1f522e8f1d8330165e98',
    'rrt-rounds': 'e3a2c6952d74e145aaec8fd9',
    'rrt-stall': '7ad5c6c6ae4696c4b1fccead',
    'rrt-critical': '0bdbaf8bb450060783349183',
    'rrt-goal-bias': '1041baf4db960f7c5d59495f',
    'rrt-errors': '5a15b2a227b1bee8c6ef1d6f',
    'rrt-corridor': '029a6412b3d40dc465b8e496',
    'rrt-lattice': '8ec019f8048d8cd76217df3f',
    'prrt-clutter-0': '6db0604c59992168b305bb60',
    'prrt-clutter-1': '0efc8b8de064d9919e62d552',
    'prrt-clutter-2': '4710753394d6421107b8e8ac',
    'prrt-calls': '4a6e0c836cb823d7aa916ad4',
    'prrt-3-stall': '7975ddfa93cbeb2e638e4c3e',
    'prrt-errors': '1269319452d8d0e05a968219',
    'prrt-goal-bias': '9e3882782246f1ec895d8951',
    'qrrt-sv-0': '93b9e97fec1d01823fea5d7c',
    'qrrt-sv-1': '59527a96e7a9a6a2319c9e27',
    'qrrt-sv-2': '5798476f1c4984beea4fba8f',
    'qrrt-sv-calls': 'cfd273210e961ca0b3bff7fa',
    'qrrt-bbht': '6e46420c4a89900f42770d88',
    'qrrt-adaptive': '2d3698ada40657fcb5ea4f70',
    'qrrt-optimal-errors': 'b6ef114585d741747e76de2a',
    'qrrt-annealing': 'c801dd21674a94f1ef594291',
    'pqrrt-shared': '1296a53e146622426363256d',
    'pqrrt-unshared': '555b287dbdc572e9a433c8a8',
    'pqrrt-shared-bbht-errors': 'b54899a40973d66a0d367c40',
    # trees past BRUTE_FORCE_BELOW (the nearest-node grid answers)
    'rrt-large': '061fe5f51988dd436adc0c41',
    'qrrt-sv-large': '95c5fc912b8654362fb38aee',
    'pqrrt-shared-large': '24da12a8e8a9eb181b3321b0',
}


def test_every_case_has_a_reference():
    assert set(REFERENCE) == set(CASES)


@pytest.mark.parametrize("case", sorted(CASES))
def test_plan_is_unchanged(case):
    assert fingerprint(run_case(case)) == REFERENCE[case]
