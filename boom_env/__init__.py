"""boom_env: Gymnasium environments on top of sim_core (telescopic extraction/retraction).

Not implemented yet: the environments depend on the telescopic boom system of sim_core
(issue "Telescopic boom system"); importing this package registers nothing so far.
"""
