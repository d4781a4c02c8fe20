"""Reading the JSON a `seamcl ... --json` command printed, for the chart scripts: every field a
chart reads is checked, and an error names the field (and the command that writes such a file)."""
import json


def load_results(path, command, fields):
    """(answer, answer["results"]) of the JSON at `path`, each result holding every name in `fields`.

    Raises ValueError naming the file and the first missing field."""
    try:
        with open(path) as f:
            answer = json.load(f)
    except (OSError, json.JSONDecodeError) as error:
        raise ValueError(f"{path}: {error}") from error
    results = answer.get("results") if isinstance(answer, dict) else None
    if not isinstance(results, list) or not results:
        raise ValueError(f"{path}: 'results' must be a non-empty list ({command})")
    for k, r in enumerate(results):
        for field in fields:
            if not isinstance(r, dict) or field not in r:
                raise ValueError(f"{path}: results[{k}].{field} is missing ({command})")
    return answer, results
