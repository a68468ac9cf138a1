"""The built-in estimators: the baselines and the filters of the seed papers (SPEC section 6).

Modules
-------
baselines     ``gnss_only`` and ``dead_reckoning``
"""
