"""synthesis: people × actions × joint-angle tensors, the N-mode SVD, motion signatures.

Vasilescu's *Human Motion Signatures* (ICPR 2002): a corpus of people performing actions is
stacked into a people × actions × (time-normalised joint angles) tensor and decomposed with
the N-mode SVD ``D = Z ×_1 P ×_2 A ×_3 J``; a person's row of ``P`` is their motion
signature, and an action basis ``B_a = Z ×_2 a_aᵀ ×_3 J`` turns a signature into that
person's motion of the action — also for actions they were never captured doing.

Modules
-------
corpus
    Corpus → :class:`~synthesis.corpus.MotionCorpus` (listing, reading trials' joint angles,
    stacking and averaging cells, missing cells).
cycles
    Time normalisation of angle curves (unwrapping, gap bridging, resampling, cycle detection
    and averaging, branch).
nmode
    :func:`~synthesis.nmode.nmode_svd` (Gram-matrix HOSVD, ranks by count or kept energy).
signature
    Action bases, signature least squares, synthesis, recognition scores, blending.
regression
    :class:`~synthesis.regression.SignatureModel`: bases from complete people, signatures by
    ridge regression, rank and ridge by leave-one-out, imputation when few people are complete.
interaction, transfer
    The predictors of a person's cells from their other cells: the additive model plus the
    N-mode SVD of its interaction residual, and the older action transfer.
methods
    Those predictors behind one interface (:class:`~synthesis.methods.CellMethod`) and the
    registry ``--method`` chooses from (:data:`~synthesis.methods.METHODS`).
model
    :class:`~synthesis.model.MotionModel`: the corpus' angle and timing signatures and one
    method for each; synthesis, blends, new people. It holds arrays and never reads a file.
recognition
    The most likely person and action of a cycle, from a method's predictions.
model_file
    The model's files: ``.npz`` save and load, a trial read the way the corpus was.
evaluate
    Leave-one-cell-out evaluation against the "mean of the other people" baseline.
plot
    Figures (captured vs synthesised vs baseline cycles, the evaluation plot), built
    without pyplot state: they take ``ax=`` or return a ``Figure``.

The commands ``mocap decompose | synthesize | recognize | evaluate`` live in
``mocap/cli/synthesis.py``.

Examples
--------
>>> from synthesis import MotionModel, load_corpus                       # doctest: +SKIP
>>> corpus = load_corpus("corpus/", markerset="synthetic15")             # doctest: +SKIP
>>> model = MotionModel().fit(corpus)                                    # doctest: +SKIP
>>> curve, seconds = model.synthesize("ana", "run")                      # doctest: +SKIP
"""
from importlib import import_module

#: Public names and their modules, imported on first use (keeps ``mocap --help`` fast).
_EXPORTS = {"MotionModel": "synthesis.model", "MotionCorpus": "synthesis.corpus",
            "load_corpus": "synthesis.corpus", "leave_one_out": "synthesis.evaluate",
            "nmode_svd": "synthesis.nmode"}

__all__ = list(_EXPORTS)


def __getattr__(name: str):
    if name in _EXPORTS:
        return getattr(import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'synthesis' has no attribute {name!r}")
