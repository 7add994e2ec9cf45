"""A function for tools/adversarial_pass.py's batch cases, importable by worker processes."""

import os
import time


def die_on_three(x):
    """x * 10 after 0.2 s (so that items are pending when one dies), except for 3, whose
    worker process dies (as a reader's segfault would)."""
    time.sleep(0.2)
    if x == 3:
        os._exit(1)
    return x * 10
