"""Counts over the concealed cases of conceal_seeds.log, from each case's answer.json and
diag.json; run in the folder the cases were written to: python3 conceal_summary.py"""
import json

for effect in ["coulomb_friction", "viscous_friction", "armature_reaction"]:
    selected, ties, fallback = {}, [], 0
    for seed in range(1, 11):
        case = f"{effect}_{seed}"
        answer = json.load(open(case + "/answer.json"))
        diag = json.load(open(case + "/diag.json"))
        selected[diag["selected"]] = selected.get(diag["selected"], 0) + 1
        fallback += answer["input_fallback"]
        if diag["ties"]:
            ties.append((seed, diag["selected"], diag["ties"]))
    print(effect, "fell back to reversal", fallback, "of 10; selected", selected, "; ties", ties)
