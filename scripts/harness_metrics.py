"""The harness's declared metrics, for the plot scripts.

results/metrics.json is what `idcol_harness metrics --json` prints (the test
harness.metrics_file fails when it differs): each metric of each study kind
with its name, the path of its group in an entry of a results file (where),
its path in the group's object (path), and its key. A plot script names a
metric by its declared name and takes the JSON keys from here, so that each
key of a results file is spelled in one source file, the harness's.
"""
import json
import os

FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "results", "metrics.json")
_declared = None


def declared(kind, name):
    """The declaration of metric `name` ("{key}.time.median_us") of study kind `kind` ("sweep")."""
    global _declared
    if _declared is None:
        with open(FILE) as f:
            _declared = {(m["kind"], m["name"]): m for m in json.load(f)}
    return _declared[(kind, name)]


def path(kind, name):
    """The metric's keys from its group's object down, a list (its dotted path split at the dots)."""
    return declared(kind, name)["path"].split(".")


def key(kind, name):
    """The key that names the metric in the results file: the last of its path that is not a summary statistic."""
    return declared(kind, name)["key"]


def where(kind, name):
    """The path of the metric's group in an entry ("cold_accuracy_pass")."""
    return declared(kind, name)["where"]
