"""The samples an encoder_glitch case miscounts, as examples/beyond_library_cases.rs draws them:
splitmix64 of the case's salt and the sample's index, one in a hundred; and the salt and size
read from the case's answer.json."""
import json, re

M = (1 << 64) - 1


def miscounted(salt, k):
    z = salt ^ ((k * 0x9E3779B97F4A7C15) & M)
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M
    z ^= z >> 31
    return z % 100 == 0


def case_truth(case):
    """The case's answer, its salt and the miscount's size a."""
    answer = json.load(open(f"{case}/answer.json"))
    salt = int(re.search(r"salt: (\d+)", answer["truth"]).group(1))
    a = float(re.search(r"a: ([0-9.e+-]+)", answer["truth"]).group(1))
    return answer, salt, a
