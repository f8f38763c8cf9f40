"""Plans do not change: every planner's tree, counters and history for fixed seeds hash to the
values computed with the code before issue 11's performance work (tests/planner_fingerprints.py
prints the table; regenerate it only for a change meant to alter results, and say so)."""

from __future__ import annotations

import pytest
from planner_fingerprints import CASES, fingerprint, run_case

REFERENCE = {
    'rrt-clutter-0': '7bcdcf143789df6f65fa7822',
    'rrt-clutter-1': '16aede094caf154ec70d0871',
    'rrt-clutter-2': 'bf0e7f63751f86cffb029f76',
    'rrt-clutter-3': 'd176734134dc72ba7c033c6a',
    'rrt-clutter-4': 'c197ba465640b1dbf75482ed',
    'rrt-clutter-5': 'b5756978281436505aac5f2d',
    'rrt-calls-0-1': '4b5322561cd90ea94b6173fc',
    'rrt-calls-1-37': '16b386278e1ff7c65e89b531',
    'rrt-calls-2-150': '6684ddc35e1156d94025f945',
    'rrt-calls-3-401': 'b839920b0c7a1ea074701d42',
    'rrt-rounds': 'f094a2e5ae23c59c44e9a263',
    'rrt-stall': '7ad5c6c6ae4696c4b1fccead',
    'rrt-critical': '27e46efbd24d27e098a411b1',
    'rrt-goal-bias': 'e3a03235e17728ecdc809d14',
    'rrt-errors': '3c4050dfe3ba2652a7012a8e',
    'rrt-corridor': '5cf188482fb2f354a6175a1b',
    'rrt-lattice': '3c014feff09d2691922111b2',
    'prrt-clutter-0': '736325f7d762c95d8425c943',
    'prrt-clutter-1': 'fa8164b44a4b14efb3140346',
    'prrt-clutter-2': 'a2019c0035279beabf283885',
    'prrt-calls': '0027ab3427d0cfb79bf00e76',
    'prrt-3-stall': '7975ddfa93cbeb2e638e4c3e',
    'prrt-errors': 'a57cf268e608a10fdf5b58de',
    'prrt-goal-bias': 'efec7f9ddea14d39b7dd45b1',
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
    # computed at 9c3c6d4 (before the nearest-node grid's rewrite; trees past BRUTE_FORCE_BELOW)
    'rrt-large': '478ce7395cc265441b68f9ab',
    'qrrt-sv-large': '95c5fc912b8654362fb38aee',
    'pqrrt-shared-large': '24da12a8e8a9eb181b3321b0',
}


def test_every_case_has_a_reference():
    assert set(REFERENCE) == set(CASES)


@pytest.mark.parametrize("case", sorted(CASES))
def test_plan_is_unchanged(case):
    assert fingerprint(run_case(case)) == REFERENCE[case]
