"""camdyn.derive: the SymPy derivation of the cam-follower model and its code generator.

Needs SymPy (``pip install camdyn[derive]``).  Never imports the camdyn
runtime.  ``python -m camdyn.derive`` regenerates ``camdyn.generated``;
``python -m camdyn.derive --check`` fails when the committed code differs.
"""
