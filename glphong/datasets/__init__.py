"""Frames written in the formats training pipelines read (docs/data_for_training.md): a BOP scene's images
(`write_bop`), COCO instance annotations (`coco_annotations`, `CocoWriter`), OpenEXR with every pass as named channels
(`save_exr`, `load_exr`, the extra 'exr') and ``.npz`` (`save_npz`, `load_npz`)."""
from glphong.datasets.bop import write_bop
from glphong.datasets.coco import CocoWriter, coco_annotations
from glphong.datasets.exr import EXR_CHANNELS, load_exr, save_exr
from glphong.datasets.npz import load_npz, save_npz

__all__ = ["write_bop", "coco_annotations", "CocoWriter", "save_exr", "load_exr", "EXR_CHANNELS", "save_npz",
           "load_npz"]
