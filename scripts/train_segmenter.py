#!/usr/bin/env python3
"""Trains the target segmentation network shipped in config/models/ and
exports it to ONNX (docs/segmenter.md).

A small UNet in the spirit of the Schmidt-EKF paper (Sec. VI-A): zero-padded
3x3 convolutions, ELU instead of batch normalisation, sub-pixel convolution
(PixelShuffle) instead of up-sampling layers; 1 grey channel in at 320x240,
1 target logit per pixel out. Data: PNG pairs written by
vimot-segmentation-data (rendered simulator images and their exact masks).

Deterministic for a seed on this machine: fixed seeds, one fixed thread count,
deterministic algorithms. Needs Debian's python3-torch, python3-onnx and
python3-pil (development only; the product runs the .onnx with OpenCV dnn).
"""
import argparse
import glob
import json
import os
import random
import sys
import time

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F
from PIL import Image

WIDTH, HEIGHT = 320, 240
# Input normalisation, the same in config/segmenter.yaml: (x - mean) * scale.
MEAN, SCALE = 127.5, 1.0 / 127.5


def block(cin, cout):
    return nn.Sequential(nn.Conv2d(cin, cout, 3, padding=1), nn.ELU(),
                         nn.Conv2d(cout, cout, 3, padding=1), nn.ELU())


class Up(nn.Module):
    """Sub-pixel convolution: a conv to 4x the channels, PixelShuffle(2)."""

    def __init__(self, cin, cout):
        super().__init__()
        self.conv = nn.Conv2d(cin, cout * 4, 3, padding=1)
        self.shuffle = nn.PixelShuffle(2)

    def forward(self, x):
        return F.elu(self.shuffle(self.conv(x)))


class UNet(nn.Module):
    def __init__(self, width=8):
        super().__init__()
        c = [width, width * 2, width * 4, width * 8]
        self.enc = nn.ModuleList([block(1, c[0]), block(c[0], c[1]), block(c[1], c[2])])
        self.bottom = block(c[2], c[3])
        self.up = nn.ModuleList([Up(c[3], c[2]), Up(c[2], c[1]), Up(c[1], c[0])])
        self.dec = nn.ModuleList([block(2 * c[2], c[2]), block(2 * c[1], c[1]), block(2 * c[0], c[0])])
        self.head = nn.Conv2d(c[0], 1, 1)

    def forward(self, x):
        skips = []
        for enc in self.enc:
            x = enc(x)
            skips.append(x)
            x = F.max_pool2d(x, 2)
        x = self.bottom(x)
        for up, dec, skip in zip(self.up, self.dec, reversed(skips)):
            x = dec(torch.cat([up(x), skip], dim=1))
        return self.head(x)


def load_set(folder):
    images = sorted(glob.glob(os.path.join(folder, "img_*.png")))
    if not images:
        sys.exit(f"train_segmenter: no img_*.png in {folder}")
    x = np.stack([np.asarray(Image.open(p), dtype=np.uint8) for p in images])
    y = np.stack([np.asarray(Image.open(p.replace("img_", "mask_")), dtype=np.uint8) > 127 for p in images])
    if x.shape[1:] != (HEIGHT, WIDTH):
        sys.exit(f"train_segmenter: {folder}: images are {x.shape[1:]}, expected {HEIGHT}x{WIDTH}")
    return x, y, images


def normalise(x_uint8):
    return (torch.from_numpy(x_uint8).float().unsqueeze(1) - MEAN) * SCALE


def crops(x, y, size, rng):
    """A training batch of size x size crops; half hold target pixels (the
    target is a few % of an image), half are anywhere."""
    bx = np.empty((len(x), size, size), np.float32)
    by = np.empty((len(x), size, size), np.float32)
    for i in range(len(x)):
        img, mask = x[i].astype(np.float32), y[i]
        ys, xs = np.nonzero(mask)
        if len(ys) and rng.random() < 0.5:
            k = rng.randrange(len(ys))
            cy = min(max(ys[k] - rng.randrange(size), 0), HEIGHT - size)
            cx = min(max(xs[k] - rng.randrange(size), 0), WIDTH - size)
        else:
            cy, cx = rng.randrange(HEIGHT - size + 1), rng.randrange(WIDTH - size + 1)
        img, mask = img[cy:cy + size, cx:cx + size], mask[cy:cy + size, cx:cx + size]
        if rng.random() < 0.5:
            img, mask = img[:, ::-1], mask[:, ::-1]
        # Lighting beyond the renderer's exposure range: gain, gamma, noise.
        img = 255.0 * (img / 255.0) ** rng.uniform(0.7, 1.4) * rng.uniform(0.6, 1.4)
        img = img + rng.gauss(0, 1) * rng.uniform(0, 4) * np.ones_like(img)
        bx[i], by[i] = np.clip(img, 0, 255), mask
    return ((torch.from_numpy(bx) - MEAN) * SCALE).unsqueeze(1), torch.from_numpy(by).unsqueeze(1)


def loss_fn(logits, target):
    bce = F.binary_cross_entropy_with_logits(logits, target)
    p = torch.sigmoid(logits)
    dice = 1 - (2 * (p * target).sum() + 1) / (p.sum() + target.sum() + 1)
    return bce + dice


@torch.no_grad()
def predict(model, x_uint8, batch=16):
    out = []
    for i in range(0, len(x_uint8), batch):
        out.append(model(normalise(x_uint8[i:i + batch])).squeeze(1).numpy())
    return np.concatenate(out)


def metrics(logits, y):
    pred = logits > 0
    tp = np.logical_and(pred, y).sum()
    fp = np.logical_and(pred, ~y).sum()
    fn = np.logical_and(~pred, y).sum()
    tn = pred.size - tp - fp - fn
    iou_target = tp / max(tp + fp + fn, 1)
    iou_background = tn / max(tn + fp + fn, 1)
    per_image = []
    for p, t in zip(pred, y):
        union = np.logical_or(p, t).sum()
        if t.any():
            per_image.append(np.logical_and(p, t).sum() / union)
    return {
        "pixel_accuracy": float((tp + tn) / pred.size),
        "iou_target": float(iou_target),
        "miou_classes": float((iou_target + iou_background) / 2),
        "miou_images": float(np.mean(per_image)) if per_image else float("nan"),
        "images": int(len(y)),
        "images_with_target": int(len(per_image)),
        "empty_images_with_false_positives": int(sum(p.any() for p, t in zip(pred, y) if not t.any())),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--train", required=True, help="folder of training PNG pairs")
    ap.add_argument("--test", required=True, help="folder of held-out PNG pairs")
    ap.add_argument("--out", required=True, help="ONNX file to write")
    ap.add_argument("--reference", help="folder for the C++ cross-check (test image, torch logits, mask)")
    ap.add_argument("--metrics", help="JSON file for the held-out figures")
    ap.add_argument("--minutes", type=float, default=22.0, help="training time budget")
    ap.add_argument("--steps", type=int, default=2000, help="optimizer steps")
    ap.add_argument("--batch", type=int, default=12)
    ap.add_argument("--lr", type=float, default=1.5e-3, help="Adam learning rate (cosine decay)")
    ap.add_argument("--crop", type=int, default=96)
    ap.add_argument("--width", type=int, default=8, help="channels of the first level")
    ap.add_argument("--threads", type=int, default=1, help="more threads are slower on a shared machine")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)
    torch.use_deterministic_algorithms(True)
    rng = random.Random(args.seed)

    xtr, ytr, _ = load_set(args.train)
    xte, yte, test_files = load_set(args.test)
    print(f"train {len(xtr)} images ({ytr.mean() * 100:.2f} % target pixels), test {len(xte)}", flush=True)

    model = UNet(args.width)
    params = sum(p.numel() for p in model.parameters())
    print(f"UNet width {args.width}: {params} parameters", flush=True)
    opt = torch.optim.Adam(model.parameters(), lr=args.lr)
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=args.steps)
    start = time.time()
    step = 0
    # The step budget is fixed so the run is reproducible; the time budget
    # only stops a slow machine early (and is reported).
    while step < args.steps:
        idx = [rng.randrange(len(xtr)) for _ in range(args.batch)]
        bx, by = crops(xtr[idx], ytr[idx], args.crop, rng)
        loss = loss_fn(model(bx), by)
        opt.zero_grad()
        loss.backward()
        opt.step()
        sched.step()
        step += 1
        if step % 100 == 0:
            print(f"step {step} loss {loss.item():.4f} {time.time() - start:.0f} s", flush=True)
        if time.time() - start > args.minutes * 60:
            print(f"time budget reached after {step} steps", flush=True)
            break
    train_s = time.time() - start
    model.eval()

    m = metrics(predict(model, xte), yte)
    m.update({"steps": step, "train_seconds": round(train_s), "parameters": params, "train_images": len(xtr),
              "torch": torch.__version__, "threads": args.threads})
    print(json.dumps(m, indent=1), flush=True)
    if args.metrics:
        with open(args.metrics, "w") as f:
            json.dump(m, f, indent=1)

    dummy = normalise(xte[:1])
    torch.onnx.export(model, dummy, args.out, input_names=["image"], output_names=["logits"], opset_version=11,
                      do_constant_folding=True)
    import onnx
    onnx.checker.check_model(onnx.load(args.out))
    print(f"wrote {args.out} ({os.path.getsize(args.out)} bytes)", flush=True)

    if args.reference:
        # The test image with the most target pixels: the C++ test runs it
        # through OpenCV dnn and compares with these logits.
        k = int(np.argmax(yte.reshape(len(yte), -1).sum(1)))
        Image.open(test_files[k]).save(os.path.join(args.reference, "segmenter_reference_image.png"))
        logits = predict(model, xte[k:k + 1])[0]
        # 16-bit PNG: logit = value / 1000 - 32 (clipped to +-32).
        q = np.round((np.clip(logits, -32, 32) + 32) * 1000).astype(np.uint16)
        Image.fromarray(q).save(os.path.join(args.reference, "segmenter_reference_logits.png"))
        print(f"reference: {test_files[k]}, {int((logits > 0).sum())} target pixels", flush=True)
        # A well-formed model of the wrong shape (2 output channels), for the
        # segmenter's model check.
        torch.onnx.export(nn.Conv2d(1, 2, 1), dummy, os.path.join(args.reference, "segmenter_wrong_output.onnx"),
                          opset_version=11)


if __name__ == "__main__":
    main()
