#!/usr/bin/env python3
"""Generate the USD fixtures luxeval's loader is tested against (tests/usd_fixtures.rs).

Run with Pixar's usd-core (the tests themselves never need Python):

    /opt/usdvenv/bin/python tools/gen_usd_fixtures.py [--luxtest-src DIR]

What it writes, all under tests/data/:
- luxtest/: the luxtest scenes (pmolodo/luxtest @ 9d555a66d0a6, CC-BY-4.0) copied byte for byte,
  with the synthetic test_*.ies files they reference (``../test_*.ies`` from usd/) and the licence.
  Every copied file is checked against the sha256 recorded in research/data/README.md.
- usd/composition/: a scene of our own that uses every composition arc (sublayer with a layer
  offset, reference with a layer offset, payload, variant sets with authored selections, inherits,
  specializes, instancing), every xformOp kind, time samples on inputs and transforms, invisible
  lights, an unauthored light of every UsdLux type, ShapingAPI with and without authored values,
  blocked values, and assets (an IES profile, a PNG) resolved relative to the layer that authored
  them. ``root.usdc`` is the root layer saved by usd-core's crate writer; ``scene.usdz`` is the whole
  scene packed by ``UsdUtils.CreateNewUsdzPackage`` (assets included).
- usd/errors/: broken scenes (malformed text, missing references and sublayers).
- usd/ancestors/: lights under an ancestor of every Xformable type (--only-ancestors).
- usd/reader/: lights written in every text form usd-core reads and openusd 0.8 alone did not,
  beside a MaterialX reference and a missing sublayer (--only-reader).
- usd/openusd/: a parity corpus of OpenUSD's own light test scenes (PixarAnimationStudios/OpenUSD
  @ v24.08, Tomorrow Open Source Technology License 1.0, LICENSE.txt beside them), copied byte for
  byte in their repository layout with the local files they reference (sha256 checked), from an
  extracted checkout given as --openusd-src. `--only-openusd` writes only these and their
  expected JSON (usd/expected/openusd_*.json); tools/usd_parity.py runs the same comparison over
  a whole checkout.
- usd/expected/*.json: what usd-core resolves for every light of every scene above, at every time
  code the scene authors and under the EarliestTime rule: type, applied schemas, visibility, world
  matrix, and every scalar input with its value, authored flag and resolved asset path.
- usd/unapplied/ (``--only-unapplied``): lights with light filters, light-link and shadow-link
  collections, shaping inputs without ShapingAPI, and ListAPI / LightListAPI light lists, some
  through a reference and an instance; usd/expected/unapplied_links.json holds what usd-core
  composes for them (targets, collection attributes, authored shaping inputs, light lists).
"""

import argparse
import hashlib
import json
import os
import shutil
import struct
import subprocess
import sys
import zipfile
import zlib

from pxr import Sdf, Usd, UsdGeom, UsdLux, UsdUtils

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
DATA = os.path.join(REPO, "tests", "data")

# sha256 of every luxtest file we copy (from research/data/README.md).
LUXTEST_FILES = {
    "LICENSE.md": "0baf4d60c8b2b107cbdb959e0f6d0bded6244de5e7e2e2ccb88869d6555ca9ad",
    "test_linear_vertical.ies": "a89db7bb18ede3709a53409884389410eb43a04b2ae7b7f1f9973db7beda2a19",
    "test_stripes_uniform.ies": "f26c8381dbc007e8c1271329f547976180b9c57537cfa2332bf33261ff0adc3d",
    "test_stripes_nonuniform.ies": "647c0fd6a35f11d7a53f1340236046781f2ce61b1f1b954086b84fa1d0dd8bf7",
    "test_vstripes_hquadrants_nonuniform.ies": "66582367293165edfc53a68ca8a486adc8ed06cd257533d91cd2e1d350dba981",
    "test_vstripes_hquadrants_nonuniform_aimDown.ies": "b4f238da7f9ddbfea22bc69b2fbb8bdc3a2daf2b2d920a2bbc7209bc6f04e648",
    "test_vstripes_hquadrants_nonuniform_aimUp.ies": "d8079b1a8874229746da49e3a229505e8869355ae91e65d242b2fb17900dd3ba",
    # The luxtest dome (and visibleRect) texture: 2048 × 1024 half RGB, ZIPS. Not in
    # research/data (too big for it): pass a luxtest checkout as --luxtest-src.
    "dome_grid_2k.exr": "ec953653188832c800b560a301eac86811d491b87e49a43c1c19ff952e16efb6",
    "usd/rect.usda": "d0fc8c543b93bd8f021e329181006d86ac9de7e4ac8db201f06964acf91d995a",
    "usd/sphere.usda": "25f00c53306a2f28ba62fd4916ebf7b733320e6bb6bb2b3f83bdb12ee4776269",
    "usd/disk.usda": "f67f08d24de4b6efb9895e4c32e59f60c961e11c3b5295fcab931d4baf8552a2",
    "usd/cylinder.usda": "da50b181bc0c0f7a7c1577baf7a8169f16c288fb2190a933fa04fe66889e5773",
    "usd/distant.usda": "259453c5cf09bc3d7d142b17cc4f32fe9b58104371a386c94cec79ddd5dbf5bf",
    "usd/dome.usda": "c3263bd2bb4285aa7ae4dbbd328ce49238b09ae322f2f52ad2c02502cb64303a",
    "usd/visibleRect.usda": "032db623e42047f91ecab6d09b7a28ddc04f74425bbfad3d59d5c8ae555f2d99",
    "usd/iesTest.usda": "0de2cd5b72fe510ebe9e36a868bcc1fb0423c97c8a70a33629a4f91aa2b7b821",
    "usd/iesLibPreview.usda": "f958c24dd943dfecd9e64298fdf734c1a092f7ab0a24f5d8c7dfd4d6aa10cc3d",
    "usd/iesUp.usda": "8b172d30b23e6e2a16b0739403e643a2d6c683caf51c1d80e228f1a14bae9b72",
    "usd/iesDown.usda": "f327120dab7aecc42d142c25df700238494ebfd6e51579fda81ed11c2392e0c8",
    "usd/shapes/sphere50x50.usda": "84d905cc33fb2c411629096a99bc7e35aac899162cdab2c13387f5c4be536e81",
}

LUXTEST_README = """\
# luxtest scenes (third-party test data)

Copied byte for byte from github.com/pmolodo/luxtest @ 9d555a66d0a6 (branch `pmolodo`,
2024-10-07), licensed CC-BY-4.0 (full text in LICENSE.md beside this file). Copied by
tools/gen_usd_fixtures.py, which checks every file's sha256.

- `usd/*.usda`, `usd/shapes/sphere50x50.usda`: the light test scenes.
- `test_*.ies`: the synthetic IES profiles the scenes reference as `../test_*.ies`. They have CRLF
  line endings on purpose (LM-63); `.gitattributes` keeps git from normalising them.
- `dome_grid_2k.exr`: the texture of the dome and visibleRect scenes (`../dome_grid_2k.exr`),
  2048 × 1024 half RGB, ZIPS (origin: anderslanglands/light_comparison, same author).

Not copied (the scenes reference them, so they resolve to nothing here): `../bega_omni002_4777lm.ies`
and `../04f377f94ce81cd7b5101fffdf571454.ies` (BEGA photometry, CC BY-ND 4.0).
"""

# OpenUSD's light test scenes: every file they need, by its path in the OpenUSD repository at
# OPENUSD_TAG, with its sha256 there. The scenes cover every light type OpenUSD's test scenes use
# (SphereLight, DomeLight, RectLight, DistantLight, DiskLight) and the constructs that stopped
# luxeval's text reader on the whole corpus (tools/usd_parity.py): a reference to a MaterialX
# .mtlx layer, asset values written as strings, `//` comments, the `config` qualifier, numbers
# written `.1` and `0.`; beside them scenes that read: payloads, sublayers, instancing, collections,
# time samples on transforms, inputs and visibility, textures that resolve.
OPENUSD_TAG = "v24.08"
OPENUSD_COMMIT = "59992d2178afcebd89273759f2bddfe730e59aa8"
OPENUSD_FILES = {
    "LICENSE.txt": "6324b95f7dcf156e6ea4d9458462739c812d2188cfa7e4447741fe953ea29d0b",
    "pxr/usd/usdLux/testenv/testUsdLuxLightListAPI/root.usda": "29464a5bff2b8c532dbcacfbfd021ae48ab82a5854be3a6bb680f0325b387915",
    "pxr/usd/usdLux/testenv/testUsdLuxLightListAPI/root_with_instances.usda": "edb933ac9f0901a3c1a0c0966d2589ee6e268b5f94b8705969f849a1227a58a8",
    "pxr/usd/usdLux/testenv/testUsdLuxLightListAPI/torch.usda": "ebcb64e70860ce26e118476f68110781ed648b352fd9f190a56132f8e8ba83e8",
    "pxr/usd/usdLux/testenv/testUsdLuxLinkingAPI/linking_example.usda": "91157ac24f836f17790734100eff21d8eaf01276f91a878bbeacda063fa9ab49",
    "pxr/usd/usdLux/testenv/testUsdLuxLinkingAPI/meshWithFaceSet.usda": "c5c7bd9a45fffce57852b9528064ac3f74863f6a899b8ed30e394f4210304f6f",
    "pxr/usdImaging/bin/testusdview/testenv/testUsdviewLightVisibility/testVarying.usda": "8cde0e8c3baca15015c62700d8042150023048071b45bf6581503acd8521d03b",
    "pxr/usdImaging/bin/testusdview/testenv/testUsdviewRenderSettingsEdits/test.usda": "cf9808e2ea5cc4d0b42bfa1ad5b9c4bf33ae59a7d470064361eda9ce7f5381a6",
    "pxr/usdImaging/bin/usdrecord/testenv/MotionBlurTest/motionBlur.usda": "846cfe80c108287200ffb3751ab3f8df09e6ae89eca52efd7fe9461f85e17047",
    "pxr/usdImaging/usdImaging/testenv/testUsdImagingDelegateChanges/inherited_primvars.usda": "eee4cf3fd7bb23328fa7276cf719f8d18a4e4c451bcc13cd6d05a3e5f49d8524",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLAnimatedLights/lightMoving.usda": "8960ed9df6d41d5920d83a8db34ad7adb7657409be08c79ffcf1b9af1bec1369",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLDomeLight/domeLightYup.usda": "7bd67aaeca68a4c1ace97c872dd0f6350e0d18fca289756f5e7c1513862d76cc",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLDomeLight/testImage.png": "8e3383a6a6de37e112f04e092fd93c37938078f7ff6c8ca3dd4fc05d82c7c228",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLInstancing/instancedCubes.usda": "177928f97c71421fa4638101cdb55b451c33e9c9f91227375150d2a28b8eeb19",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLInstancing/lightGray.png": "4e80275fd38685ee4f317f775628d151053a9101d554ca73d3dd99e17681c52e",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXBasic/mtlxFiles/standard_surface_default.mtlx": "d9a8055550be959c573150a50e90cf418c175c076fbb384cc410157306d3155f",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXBasic/mxLights.usda": "16b3dfaa4d3648388dd872b49f4407f3e576d5715adc87b4dfa04b3e6f429830",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXvsNative/mtlxFiles/normalMap.png": "97cb0a805ac833250ef095d215bc6436292e7216a3a5554e75b563411f54d277",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXvsNative/nativeEmissive.usda": "2ccc63431b828795ccda62cf013f27cb7a9fc34706445afd843868dccfcc94e6",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXvsNative/nativeNormalMap.usda": "da0100dbd0d43a1cea24c59cb7d2c67fcb27cb967b4f05cfb4d9ab5d5252ac01",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLPointInstancer/ni_pi_xform.usda": "07276578178ad01a1e3b50095a1e671a68dba17e3008906fa227c8b64636783b",
    "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLPointInstancer/pi_pi_xform.usda": "1f48e595090624941efa0d92f8eff0fcad8f17cab99f661db28fc7495b212efb",
}

# Not copied (too big for the repository; neither holds a light):
# - testUsdLuxLightListAPI/teapot.usda (1.1 MB of mesh, referenced by root.usda as
#   /World/Geo/teapot): replaced by OPENUSD_TEAPOT_STANDIN, a prim of the same name and type with
#   nothing under it, so that the reference composes and every light is where it was.
# - testUsdImagingGLMaterialXvsNative/StinsonBeach.hdr (1.4 MB, nativeEmissive.usda's dome
#   texture): absent, so its inputs:texture:file resolves to nothing here, in usd-core as in
#   luxeval (the expected JSON is usd-core's reading of the copy).
OPENUSD_TEAPOT = "pxr/usd/usdLux/testenv/testUsdLuxLightListAPI/teapot.usda"
OPENUSD_TEAPOT_STANDIN = """#usda 1.0
(
    defaultPrim = "teapot_Base"
    doc = "luxeval: a stand-in for OpenUSD's teapot.usda (1.1 MB of mesh, no light), written by tools/gen_usd_fixtures.py; the prim root.usda references, with nothing under it"
)

def Mesh "teapot_Base" (
    kind = "model"
)
{
}
"""

# (fixture name, scene): each becomes usd/expected/openusd_<name>.json.
OPENUSD_SCENES = [
    ("light_list_root", "pxr/usd/usdLux/testenv/testUsdLuxLightListAPI/root.usda"),
    ("light_list_root_with_instances", "pxr/usd/usdLux/testenv/testUsdLuxLightListAPI/root_with_instances.usda"),
    ("linking_example", "pxr/usd/usdLux/testenv/testUsdLuxLinkingAPI/linking_example.usda"),
    ("usdview_light_visibility_varying", "pxr/usdImaging/bin/testusdview/testenv/testUsdviewLightVisibility/testVarying.usda"),
    ("usdview_render_settings_edits", "pxr/usdImaging/bin/testusdview/testenv/testUsdviewRenderSettingsEdits/test.usda"),
    ("usdrecord_motion_blur", "pxr/usdImaging/bin/usdrecord/testenv/MotionBlurTest/motionBlur.usda"),
    ("delegate_inherited_primvars", "pxr/usdImaging/usdImaging/testenv/testUsdImagingDelegateChanges/inherited_primvars.usda"),
    ("gl_animated_light_moving", "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLAnimatedLights/lightMoving.usda"),
    ("gl_dome_light_yup", "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLDomeLight/domeLightYup.usda"),
    ("gl_instanced_cubes", "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLInstancing/instancedCubes.usda"),
    ("gl_mx_lights", "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXBasic/mxLights.usda"),
    ("gl_native_emissive", "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXvsNative/nativeEmissive.usda"),
    ("gl_native_normal_map", "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXvsNative/nativeNormalMap.usda"),
    ("gl_point_instancer_ni_pi_xform", "pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLPointInstancer/ni_pi_xform.usda"),
]

OPENUSD_README = """\
# OpenUSD light test scenes (third-party test data)

Copied byte for byte from github.com/PixarAnimationStudios/OpenUSD at tag `{tag}` (commit
`{commit}`), in the repository's own layout (`pxr/...` here is `pxr/...` there), by
`tools/gen_usd_fixtures.py --only-openusd`, which checks every file's sha256. Licensed under the
Tomorrow Open Source Technology License 1.0 (OpenUSD's `LICENSE.txt`, copied beside this file).

They are luxeval's parity corpus (`tests/usd_parity.rs`): every light of every scene below must
read as usd-core reads it (`../expected/openusd_<name>.json`, written by usd-core only).
`tools/usd_parity.py` runs the same comparison over a whole OpenUSD checkout.

| fixture | scene (path in OpenUSD) | lights | what it exercises |
| --- | --- | --- | --- |
{rows}

Not copied (too big, and neither holds a light):

- `pxr/usd/usdLux/testenv/testUsdLuxLightListAPI/teapot.usda` (1.1 MB of mesh, referenced by
  `root.usda`): `teapot.usda` here is **our stand-in**, not OpenUSD's file: the prim `root.usda`
  references (`Mesh "teapot_Base"`, the default prim) with nothing under it, so that the reference
  composes and every light is where it was.
- `pxr/usdImaging/usdImagingGL/testenv/testUsdImagingGLMaterialXvsNative/StinsonBeach.hdr`
  (1.4 MB, the dome texture of `nativeEmissive.usda`): absent, so that light's
  `inputs:texture:file` resolves to nothing here, in usd-core as in luxeval.
"""

OPENUSD_NOTES = {
    "light_list_root": "a `//` comment (line 47); payloads and a reference (the teapot stand-in)",
    "light_list_root_with_instances": "`root.usda` as a sublayer (its `//` comment), instanceable payloads: lights as instance proxies",
    "linking_example": "8 sphere lights with light-link collections, a reference",
    "usdview_light_visibility_varying": "time-sampled visibility, startTimeCode 1 to 10, most LightAPI inputs authored",
    "usdview_render_settings_edits": "the `config` qualifier (line 94); `inputs:focus` on a RectLight without ShapingAPI",
    "usdrecord_motion_blur": "time-sampled transforms, startTimeCode 1 to 10",
    "delegate_inherited_primvars": "a rect light with most LightAPI inputs authored, startTimeCode 1",
    "gl_animated_light_moving": "time-sampled transforms, startTimeCode 1 to 3",
    "gl_dome_light_yup": "`asset inputs:texture:file = \"testImage.png\"`, an asset written as a string (line 53); startTimeCode 1",
    "gl_instanced_cubes": "a dome texture that resolves (`lightGray.png`), instanceable prims",
    "gl_mx_lights": "a reference to a MaterialX `.mtlx` layer (which pip's usd-core cannot open either: it composes the stage without it, with a warning); disk and distant lights",
    "gl_native_emissive": "numbers written `0.` (line 62); its dome texture is not copied",
    "gl_native_normal_map": "numbers written `.1` (line 101)",
    "gl_point_instancer_ni_pi_xform": "a reference to another scene, instancing",
}

LIGHT_TYPES = {
    "DistantLight", "SphereLight", "DiskLight", "RectLight", "CylinderLight", "DomeLight",
    "DomeLight_1", "PortalLight", "GeometryLight", "PluginLight",
}
LIGHT_APIS = ("MeshLightAPI", "VolumeLightAPI")

# ---------------------------------------------------------------------------------------------
# The composition scene. Written as text so that a reader sees exactly what is authored.

ROOT_USDA = """\
#usda 1.0
(
    doc = "luxeval composition fixture, generated by tools/gen_usd_fixtures.py: every composition arc, every xformOp kind, time samples, visibility, fallbacks"
    metersPerUnit = 0.5
    upAxis = "Z"
    subLayers = [
        @layers/sublayer.usda@ (offset = 2; scale = 0.5)
    ]
)

class "_LightClass"
{
    float inputs:exposure = 2
    color3f inputs:color = (1, 0.5, 0.25)
}

class Xform "_AbstractRig"
{
    def SphereLight "NotListed"
    {
    }
}

def Xform "World"
{
    double3 xformOp:translate = (0, 0, 1)
    float xformOp:rotateZ = 90
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateZ"]

    def Scope "Defaults"
    {
        def DistantLight "Distant"
        {
        }
        def SphereLight "Sphere"
        {
        }
        def DiskLight "Disk"
        {
        }
        def RectLight "Rect"
        {
        }
        def CylinderLight "Cylinder"
        {
        }
        def DomeLight "Dome"
        {
        }
        def DomeLight_1 "Dome1"
        {
        }
        def PortalLight "Portal"
        {
        }
        def GeometryLight "Geometry"
        {
        }
        def PluginLight "Plugin"
        {
        }
        def Mesh "MeshLight" (
            prepend apiSchemas = ["MeshLightAPI"]
        )
        {
        }
        def Volume "VolumeLight" (
            prepend apiSchemas = ["VolumeLightAPI"]
        )
        {
        }
        def DiskLight "ShapedDefaults" (
            prepend apiSchemas = ["ShapingAPI", "ShadowAPI"]
        )
        {
        }
    }

    def Xform "Rig" (
        prepend references = @rig/rig.usda@</Rig> (offset = 1; scale = 2)
        variants = {
            string mood = "cool"
        }
    )
    {
        over "Spot"
        {
            float inputs:specular = 0.25
            float inputs:diffuse = None
        }
    }

    def Xform "Instanced" (
        instanceable = true
        prepend references = @rig/rig.usda@</Rig>
    )
    {
        double3 xformOp:translate = (10, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }

    def Xform "Env" (
        prepend payload = @env/env.usda@</Env>
    )
    {
    }

    def Xform "Switch" (
        variants = {
            string shape = "disk"
        }
        prepend variantSets = "shape"
    )
    {
        variantSet "shape" = {
            "disk" {
                def DiskLight "Light"
                {
                    float inputs:radius = 0.25
                    float inputs:intensity = 7
                }
            }
            "rect" {
                def RectLight "Light"
                {
                    float inputs:width = 3
                }
            }
        }
    }

    def SphereLight "Inherited" (
        prepend inherits = </_LightClass>
    )
    {
        float inputs:intensity = 3
    }

    def DiskLight "Specialized" (
        prepend specializes = </_LightClass>
    )
    {
        float inputs:exposure = 1
    }

    def Xform "Shaped"
    {
        def DiskLight "Cone" (
            prepend apiSchemas = ["ShapingAPI"]
        )
        {
            float inputs:intensity = 40
            float inputs:shaping:cone:angle = 35
            float inputs:shaping:cone:softness = 0.3
            float inputs:shaping:focus = 1.5
            color3f inputs:shaping:focusTint = (0.2, 0.4, 0.6)
            asset inputs:shaping:ies:file = @@
        }
        def SphereLight "Ies" (
            prepend apiSchemas = ["ShapingAPI"]
        )
        {
            asset inputs:shaping:ies:file = @ies/spot.ies@
            float inputs:shaping:ies:angleScale = -0.5
        }
        def RectLight "Textured"
        {
            asset inputs:texture:file = @env/sky.png@
        }
        def RectLight "MissingTexture"
        {
            asset inputs:texture:file = @env/does_not_exist.png@
        }
    }

    def Xform "OpsA"
    {
        double3 xformOp:translate = (1, 2, 3)
        double xformOp:translateX = 0.5
        float xformOp:translateY = -0.25
        half xformOp:translateZ = 0.125
        float3 xformOp:scale = (1, 2, 0.5)
        double xformOp:scaleX = 1.5
        float xformOp:scaleY = 0.75
        half xformOp:scaleZ = 2
        float xformOp:rotateX = 30
        double xformOp:rotateY = -45
        half xformOp:rotateZ = 60
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:translateX", "xformOp:translateY", "xformOp:translateZ", "xformOp:scale", "xformOp:scaleX", "xformOp:scaleY", "xformOp:scaleZ", "xformOp:rotateX", "xformOp:rotateY", "xformOp:rotateZ"]

        def Xform "OpsB"
        {
            float3 xformOp:rotateXYZ = (10, 20, 30)
            double3 xformOp:rotateXZY = (-15, 25, 35)
            half3 xformOp:rotateYXZ = (5, 10, 15)
            float3 xformOp:rotateYZX = (40, -30, 20)
            float3 xformOp:rotateZXY = (12, 34, 56)
            double3 xformOp:rotateZYX = (-60, 45, -30)
            uniform token[] xformOpOrder = ["xformOp:rotateXYZ", "xformOp:rotateXZY", "xformOp:rotateYXZ", "xformOp:rotateYZX", "xformOp:rotateZXY", "xformOp:rotateZYX"]

            def Xform "OpsC"
            {
                double3 xformOp:translate:pivot = (0.1, 0.2, 0.3)
                quatf xformOp:orient = (0.9238795, 0, 0.3826834, 0)
                quatd xformOp:orient:exact = (0.5, 0.5, 0.5, 0.5)
                matrix4d xformOp:transform = ( (1, 0.2, 0, 0), (0, 1, 0.3, 0), (0.1, 0, 1, 0), (4, 5, 6, 1) )
                float xformOp:rotateX:undo = 20
                uniform token[] xformOpOrder = ["xformOp:translate:pivot", "xformOp:orient", "xformOp:orient:exact", "xformOp:transform", "xformOp:rotateX:undo", "!invert!xformOp:rotateX:undo", "!invert!xformOp:translate:pivot"]

                def RectLight "AllOps"
                {
                    float inputs:width = 2
                    float inputs:height = 3
                    double3 xformOp:translate = (0, 0, -1)
                    uniform token[] xformOpOrder = ["xformOp:translate"]
                }

                def SphereLight "Reset"
                {
                    double3 xformOp:translate = (7, 8, 9)
                    uniform token[] xformOpOrder = ["!resetXformStack!", "xformOp:translate"]
                }

                def Xform "InvertedMatrix"
                {
                    matrix4d xformOp:transform = ( (2, 0, 0, 0), (0, 4, 0, 0), (0, 0, 0.5, 0), (1, 2, 3, 1) )
                    uniform token[] xformOpOrder = ["!invert!xformOp:transform"]

                    def CylinderLight "Child"
                    {
                    }
                }
            }
        }
    }

    def RectLight "Anim"
    {
        float inputs:intensity.timeSamples = {
            1: 10,
            3: 30,
        }
        color3f inputs:color.timeSamples = {
            1: (1, 0, 0),
            3: (0, 0, 1),
        }
        bool inputs:normalize.timeSamples = {
            1: 0,
            2: 1,
        }
        asset inputs:texture:file.timeSamples = {
            1: @@,
            3: @env/sky.png@,
        }
        float inputs:width = 5
        float inputs:width.timeSamples = {
            2: 1,
        }
        float inputs:exposure.timeSamples = {
            1: 1,
            2: None,
            3: 3,
        }
        double3 xformOp:translate.timeSamples = {
            1: (0, 0, 0),
            3: (2, 4, 6),
        }
        float3 xformOp:rotateXYZ.timeSamples = {
            1: (0, 0, 0),
            3: (90, 45, 30),
        }
        matrix4d xformOp:transform.timeSamples = {
            1: ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1) ),
            3: ( (2, 0, 0, 0), (0, 1, 0, 0), (0, 0.5, 1, 0), (1, 1, 1, 1) ),
        }
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:transform"]
    }

    def Xform "QuatD"
    {
        quatd xformOp:orient.timeSamples = {
            0: (0.9238795325112867, 0.3826834323650898, 0, 0),
            4: (0.5, -0.5, 0.5, 0.5),
        }
        uniform token[] xformOpOrder = ["xformOp:orient"]

        def SphereLight "Child"
        {
        }
    }

    def Xform "QuatH"
    {
        half3 xformOp:translate = (1, 0, 0)
        quath xformOp:orient.timeSamples = {
            0: (1, 0, 0, 0),
            4: (0.70703125, 0, 0, 0.70703125),
        }
        uniform token[] xformOpOrder = ["xformOp:translate", "!invert!xformOp:orient"]

        def DiskLight "Child"
        {
        }
    }

    def SphereLight "Blocked"
    {
        double3 xformOp:translate.timeSamples = {
            1: (1, 0, 0),
            2: None,
            3: (3, 0, 0),
        }
        uniform token[] xformOpOrder = ["xformOp:translate"]
        token visibility.timeSamples = {
            1: "invisible",
            2: None,
            3: "inherited",
        }
    }

    def Xform "Hidden"
    {
        token visibility = "invisible"

        def SphereLight "HiddenByParent"
        {
        }
    }

    def SphereLight "HiddenSelf"
    {
        token visibility = "invisible"
    }

    def DistantLight "Blink"
    {
        token visibility.timeSamples = {
            0: "invisible",
            2: "inherited",
        }
    }

    def "Untyped"
    {
        token visibility = "invisible"

        def SphereLight "UnderUntyped"
        {
        }
    }

    def Xform "Inactive" (
        active = false
    )
    {
        def SphereLight "Off"
        {
        }
    }

    def DiskLight "NegativeRadius"
    {
        float inputs:radius = -1
    }

    def SphereLight "DoubleTyped"
    {
        double inputs:intensity = 2.5
    }
}
"""

SUBLAYER_USDA = """\
#usda 1.0
(
    doc = "Sublayer of root.usda (offset 2, scale 0.5): weaker opinions and its own lights"
)

over "World"
{
    def DistantLight "Sun"
    {
        float inputs:angle.timeSamples = {
            0: 1,
            10: 3,
        }
        float inputs:intensity = 10
        float xformOp:rotateX = -45
        uniform token[] xformOpOrder = ["xformOp:rotateX"]
    }

    def SphereLight "SubSpot" (
        prepend apiSchemas = ["ShapingAPI"]
    )
    {
        asset inputs:shaping:ies:file = @../ies/spot.ies@
    }

    over "Shaped"
    {
        over "Cone"
        {
            float inputs:intensity = 999
            float inputs:specular = 0.5
        }
    }
}
"""

RIG_USDA = """\
#usda 1.0
(
    defaultPrim = "Rig"
)

def Xform "Rig" (
    variants = {
        string mood = "warm"
    }
    prepend variantSets = "mood"
)
{
    double3 xformOp:translate = (0, 1, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def SphereLight "Spot" (
        prepend apiSchemas = ["ShapingAPI"]
    )
    {
        float inputs:intensity.timeSamples = {
            0: 100,
            4: 500,
        }
        float inputs:diffuse = 0.5
        float inputs:radius = 0.1
        float inputs:shaping:cone:angle = 30
        float inputs:shaping:cone:softness = 0.25
        float inputs:shaping:focus = 2
        color3f inputs:shaping:focusTint = (1, 0.5, 0)
        asset inputs:shaping:ies:file = @../ies/spot.ies@
        float inputs:shaping:ies:angleScale = 0.5
        bool inputs:shaping:ies:normalize = 1
        quatf xformOp:orient.timeSamples = {
            0: (1, 0, 0, 0),
            4: (0, 0, 1, 0),
        }
        uniform token[] xformOpOrder = ["xformOp:orient"]
    }

    def RectLight "Fill"
    {
        float inputs:width = 2
        float inputs:height = 0.5
        bool inputs:normalize = 1
    }

    variantSet "mood" = {
        "cool" {
            over "Fill"
            {
                color3f inputs:color = (0.6, 0.8, 1)
                bool inputs:enableColorTemperature = 1
                float inputs:colorTemperature = 8000
            }
        }
        "warm" {
            over "Fill"
            {
                color3f inputs:color = (1, 0.8, 0.6)
            }
        }
    }
}
"""

ENV_USDA = """\
#usda 1.0
(
    defaultPrim = "Env"
)

def Xform "Env"
{
    def DomeLight "Sky"
    {
        asset inputs:texture:file = @sky.png@
        token inputs:texture:format.timeSamples = {
            0: "latlong",
            5: "angular",
        }
        float inputs:intensity = 0.5
    }

    def DomeLight_1 "Uniform"
    {
        uniform token poleAxis = "Z"
        float inputs:intensity = 2
        float guideRadius = 50
        float xformOp:rotateY = 30
        uniform token[] xformOpOrder = ["xformOp:rotateY"]
    }
}
"""

# A small, valid LM-63-2002 Type C profile, CRLF as the standard asks.
SPOT_IES = (
    "IESNA:LM-63-2002\r\n"
    "[TEST] luxeval composition fixture\r\n"
    "[MANUFAC] luxeval\r\n"
    "TILT=NONE\r\n"
    "1 1000 1 3 1 1 2 0 0 0\r\n"
    "1 1 10\r\n"
    "0 45 90\r\n"
    "0\r\n"
    "100 80 10\r\n"
)

ERRORS = {
    # Line 5 is where the parser meets the stray token.
    "malformed.usda": "#usda 1.0\n\ndef Xform \"World\"\n{\n    float inputs:intensity = = 3\n}\n",
    "missing_reference.usda": (
        "#usda 1.0\n\ndef Xform \"World\"\n{\n"
        "    def SphereLight \"Ok\"\n    {\n    }\n"
        "    def Xform \"Broken\" (\n        prepend references = @missing_layer.usda@</Rig>\n    )\n    {\n    }\n}\n"
    ),
    "missing_sublayer.usda": (
        "#usda 1.0\n(\n    subLayers = [\n        @missing_sublayer_target.usda@\n    ]\n)\n\n"
        "def SphereLight \"Ok\"\n{\n}\n"
    ),
    "malformed_reference.usda": (
        "#usda 1.0\n\ndef Xform \"World\" (\n    prepend references = @malformed.usda@</World>\n)\n{\n}\n"
    ),
    "not_usd.usda": "this is not a USD file\n",
    # Splines (USD 25.05+), which usd-core evaluates and openusd 0.8 does not.
    "spline_input.usda": (
        "#usda 1.0\n\ndef SphereLight \"L\"\n{\n    float inputs:intensity.spline = {\n"
        "        bezier,\n        1: 10; post held,\n        3: 30,\n    }\n}\n"
    ),
    "spline_xform.usda": (
        "#usda 1.0\n\ndef Xform \"Rig\"\n{\n    double xformOp:rotateX.spline = {\n"
        "        bezier,\n        1: 0,\n        3: 90,\n    }\n"
        "    uniform token[] xformOpOrder = [\"xformOp:rotateX\"]\n\n"
        "    def SphereLight \"L\"\n    {\n    }\n}\n"
    ),
    # A text layer without a spline whose light takes one through a reference (the reader
    # asks about splines only where a layer read may hold one).
    "spline_referenced.usda": (
        "#usda 1.0\n\ndef Xform \"World\"\n{\n    def \"L\" (\n"
        "        prepend references = @spline_input.usda@</L>\n    )\n    {\n    }\n}\n"
    ),
    # One light whose transform cannot be computed (the inverse of a singular matrix) beside a
    # healthy one: the first is listed with a warning, the second still evaluates.
    "singular_invert.usda": (
        "#usda 1.0\n\ndef Xform \"World\"\n{\n"
        "    def SphereLight \"Broken\"\n    {\n"
        "        matrix4d xformOp:transform = ( (1, 0, 0, 0), (0, 0, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1) )\n"
        "        uniform token[] xformOpOrder = [\"!invert!xformOp:transform\"]\n    }\n"
        "    def SphereLight \"Fine\"\n    {\n    }\n}\n"
    ),
}


def png_bytes(width, height, rgb):
    """A minimal 8-bit RGB PNG (stdlib only), so the dome texture is our own file."""

    def chunk(kind, payload):
        body = kind + payload
        return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    raw = b"".join(b"\x00" + bytes(rgb[y * width * 3:(y + 1) * width * 3]) for y in range(height))
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
        + chunk(b"IDAT", zlib.compress(raw, 9))
        + chunk(b"IEND", b"")
    )


def pin_zip_timestamps(path):
    """Sets every entry's DOS modification time to 1980-01-01 00:00 in place, so that
    regenerating a usdz gives the same bytes. Only the time/date fields change: sizes, offsets
    and the 64-byte data alignment usdz requires stay as usd-core wrote them."""
    with open(path, "r+b") as f:
        data = bytearray(f.read())
        infos = zipfile.ZipFile(path).infolist()
        for info in infos:
            o = info.header_offset
            assert data[o:o + 4] == b"PK\x03\x04", path
            data[o + 10:o + 14] = struct.pack("<HH", 0, 0x21)
        eocd = data.rindex(b"PK\x05\x06")
        count, _, cd = struct.unpack_from("<HII", data, eocd + 10)
        assert count == len(infos), path
        o = cd
        for _ in range(count):
            assert data[o:o + 4] == b"PK\x01\x02", path
            data[o + 12:o + 16] = struct.pack("<HH", 0, 0x21)
            n, m, k = struct.unpack_from("<HHH", data, o + 28)
            o += 46 + n + m + k
        f.seek(0)
        f.write(data)


def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    mode = "wb" if isinstance(data, bytes) else "w"
    with open(path, mode, **({} if mode == "wb" else {"newline": ""})) as f:
        f.write(data)


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def copy_luxtest(src):
    dst = os.path.join(DATA, "luxtest")
    for rel, digest in sorted(LUXTEST_FILES.items()):
        s = os.path.join(src, rel)
        got = sha256(s)
        if got != digest:
            sys.exit(f"{s}: sha256 {got} does not match the recorded {digest}")
        d = os.path.join(dst, rel)
        os.makedirs(os.path.dirname(d), exist_ok=True)
        shutil.copyfile(s, d)
        os.chmod(d, 0o644)
    write(os.path.join(dst, "README.md"), LUXTEST_README)


def openusd_bytes(rel, src, git_dir):
    """One file of OpenUSD at OPENUSD_TAG: from the extracted tree `src` when it holds it, else
    from the git repository `git_dir` (`git show TAG:path`)."""
    path = os.path.join(src, rel)
    if os.path.isfile(path):
        with open(path, "rb") as f:
            return f.read()
    try:
        return subprocess.run(["git", "-C", git_dir, "show", f"{OPENUSD_TAG}:{rel}"],
                              check=True, capture_output=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        sys.exit(f"{rel}: not in {src}, nor at {OPENUSD_TAG} in {git_dir} ({e})")


def copy_openusd(src, git_dir):
    dst = os.path.join(DATA, "usd", "openusd")
    if os.path.isdir(dst):
        shutil.rmtree(dst)
    for rel, digest in sorted(OPENUSD_FILES.items()):
        data = openusd_bytes(rel, src, git_dir)
        got = hashlib.sha256(data).hexdigest()
        if got != digest:
            sys.exit(f"{rel}: sha256 {got} does not match the recorded {digest}")
        write(os.path.join(dst, rel), data)
    write(os.path.join(dst, OPENUSD_TEAPOT), OPENUSD_TEAPOT_STANDIN.encode("ascii"))
    rows = []
    for name, rel in OPENUSD_SCENES:
        stage = Usd.Stage.Open(os.path.join(dst, rel))
        types = sorted({str(p.GetTypeName()) for p in lights_of(stage)})
        rows.append(f"| `{name}` | `{rel}` | {', '.join(types)} | {OPENUSD_NOTES[name]} |")
    write(os.path.join(dst, "README.md"),
          OPENUSD_README.format(tag=OPENUSD_TAG, commit=OPENUSD_COMMIT, rows="\n".join(rows)))


def dump_openusd():
    for name, rel in OPENUSD_SCENES:
        layer = Sdf.Layer.FindOrOpen(os.path.join(DATA, "usd", "openusd", rel))
        # Every integer frame a scene with startTimeCode and endTimeCode authors (its first is
        # luxeval's default time), beside EarliestTime (the default of a scene without them).
        dump("usd/openusd/" + rel, "openusd_" + name,
             None if layer.HasStartTimeCode() and layer.HasEndTimeCode() else [])


def write_composition():
    comp = os.path.join(DATA, "usd", "composition")
    if os.path.isdir(comp):
        shutil.rmtree(comp)
    write(os.path.join(comp, "root.usda"), ROOT_USDA)
    write(os.path.join(comp, "layers", "sublayer.usda"), SUBLAYER_USDA)
    write(os.path.join(comp, "rig", "rig.usda"), RIG_USDA)
    write(os.path.join(comp, "env", "env.usda"), ENV_USDA)
    write(os.path.join(comp, "ies", "spot.ies"), SPOT_IES.encode("ascii"))
    # 4 × 2 lat-long: top row warm, bottom row cool.
    write(
        os.path.join(comp, "env", "sky.png"),
        png_bytes(4, 2, [255, 200, 120] * 4 + [40, 60, 120] * 4),
    )
    # The same root layer written by usd-core's crate (binary) writer.
    root = Sdf.Layer.FindOrOpen(os.path.join(comp, "root.usda"))
    if not root.Export(os.path.join(comp, "root.usdc")):
        sys.exit("exporting root.usdc failed")
    # The whole scene packed with its layers and assets in the same relative layout, root layer
    # first as the usdz spec requires, so every authored path means the same inside the package.
    cwd = os.getcwd()
    os.chdir(comp)
    try:
        with Sdf.ZipFileWriter.CreateNew("scene.usdz") as zw:
            for rel in ("root.usda", "layers/sublayer.usda", "rig/rig.usda", "env/env.usda",
                        "env/sky.png", "ies/spot.ies"):
                zw.AddFile(rel, rel)
        # A package made the way most usdz files are: UsdUtils collects the rig and the IES
        # profile it references from outside its folder, renaming paths as it sees fit.
        if not UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath("rig/rig.usda"), "rig_packaged.usdz"):
            sys.exit("CreateNewUsdzPackage failed")
        for pkg in ("scene.usdz", "rig_packaged.usdz"):
            pin_zip_timestamps(pkg)
    finally:
        os.chdir(cwd)

    errs = os.path.join(DATA, "usd", "errors")
    if os.path.isdir(errs):
        shutil.rmtree(errs)
    for name, text in ERRORS.items():
        write(os.path.join(errs, name), text)
    # The spline scene as usd-core's crate writer stores it (crate version 0.12).
    if not Sdf.Layer.FindOrOpen(os.path.join(errs, "spline_input.usda")).Export(
        os.path.join(errs, "spline_input.usdc")
    ):
        sys.exit("exporting spline_input.usdc failed")


# ---------------------------------------------------------------------------------------------
# Expectations


def rel_resolved(resolved):
    """A resolved path relative to tests/data (the fixtures must not hold this machine's paths)."""
    if not resolved:
        return None
    prefix = DATA + os.sep
    if resolved.startswith(prefix):
        return resolved[len(prefix):].replace(os.sep, "/")
    return resolved


def value_json(v, type_name):
    t = str(type_name)
    if v is None:
        return None
    if t in ("float", "double", "half"):
        return float(v)
    if t == "bool":
        return bool(v)
    if t in ("color3f", "float3", "double3", "color3d"):
        return [float(x) for x in v]
    if t == "token" or t == "string":
        return str(v)
    if t == "asset":
        return {"authored": v.path, "resolved": rel_resolved(v.resolvedPath)}
    raise TypeError(f"unexpected attribute type {t}")


SCALAR_TYPES = {"float", "double", "half", "bool", "color3f", "color3d", "float3", "double3", "token", "asset", "string"}


def light_record(prim, time, xf_cache):
    applied = [str(s) for s in prim.GetAppliedSchemas()]
    authored_api = [str(s) for s in prim.GetPrimTypeInfo().GetAppliedAPISchemas()]
    img = UsdGeom.Imageable(prim)
    visible = (img.ComputeVisibility(time) != UsdGeom.Tokens.invisible) if img else True
    m = xf_cache.GetLocalToWorldTransform(prim)
    inputs = []
    for attr in prim.GetAttributes():
        name = attr.GetName()
        t = str(attr.GetTypeName())
        if t not in SCALAR_TYPES:
            continue
        if not (name.startswith("inputs:") or name in (
                "treatAsPoint", "treatAsLine", "guideRadius", "poleAxis",
                # A mesh light's uniform attributes (luxeval's schema table rows for Mesh and
                # MeshLightAPI); other Gprims' (a Volume light's) are recorded and not compared.
                "orientation", "doubleSided", "subdivisionScheme")):
            # LightAPI declares light:materialSyncMode too (fallback noMaterialResponse), but
            # luxeval reads it only where MeshLightAPI overrides it (materialGlowTintsLight).
            if not (name == "light:materialSyncMode" and prim.HasAPI(UsdLux.MeshLightAPI)):
                continue
        inputs.append({
            "name": name,
            "type": t,
            "value": value_json(attr.Get(time), t),
            "authored": bool(attr.HasAuthoredValue()),
        })
    return {
        "path": str(prim.GetPath()),
        "type": str(prim.GetTypeName()),
        "applied_schemas": applied,
        "authored_api_schemas": authored_api,
        "visible": bool(visible),
        "world": [[float(m[r][c]) for c in range(4)] for r in range(4)],
        "inputs": inputs,
    }


def is_light(prim):
    if str(prim.GetTypeName()) in LIGHT_TYPES:
        return True
    return any(str(s) in LIGHT_APIS for s in prim.GetAppliedSchemas())


def lights_of(stage):
    return [p for p in stage.Traverse(Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)) if is_light(p)]


def dump(scene_rel, out_name, times):
    path = os.path.join(DATA, scene_rel)
    stage = Usd.Stage.Open(path)
    if stage is None:
        sys.exit(f"cannot open {path}")
    lights = lights_of(stage)
    layer = stage.GetRootLayer()
    start = layer.startTimeCode if layer.HasStartTimeCode() else None
    end = layer.endTimeCode if layer.HasEndTimeCode() else None
    if times is None:
        # Every integer frame the scene authors.
        times = list(range(int(start), int(end) + 1))
    samples = []
    for t in [None] + list(times):
        tc = Usd.TimeCode.EarliestTime() if t is None else Usd.TimeCode(t)
        cache = UsdGeom.XformCache(tc)
        samples.append({"time": t, "lights": [light_record(p, tc, cache) for p in lights]})
    out = {
        "generator": "tools/gen_usd_fixtures.py",
        "usd_version": ".".join(str(x) for x in Usd.GetVersion()),
        "scene": scene_rel,
        "up_axis": str(UsdGeom.GetStageUpAxis(stage)),
        "meters_per_unit": float(UsdGeom.GetStageMetersPerUnit(stage)),
        "start_time_code": start,
        "end_time_code": end,
        "samples": samples,
    }
    dst = os.path.join(DATA, "usd", "expected", out_name + ".json")
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    with open(dst, "w") as f:
        json.dump(out, f, indent=None, separators=(",", ":"))
        f.write("\n")
    print(f"{dst}: {len(lights)} lights x {len(samples)} times")


COMPOSITION_TIMES = [-1, 0, 1, 1.5, 2, 2.25, 3, 4.5, 7, 10]

# Lights under every kind of Xformable ancestor (usd-core composes each one's xformOps into the
# world matrix) and under prims that are not Xformable (an untyped prim, a Scope: their ops are
# ignored). A time-sampled op checks that ancestors are read at the query time too.
ANCESTORS_USDA = """#usda 1.0
(
    startTimeCode = 0
    endTimeCode = 2
)

def SkelRoot "Rig"
{
    double3 xformOp:translate = (0, 5, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def Skeleton "Skel"
    {
        float xformOp:rotateY.timeSamples = {
            0: 0,
            2: 90,
        }
        double3 xformOp:translate = (1, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateY"]

        def RectLight "Key"
        {
            double3 xformOp:translate = (0, 0, 1)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
    }
}

def Volume "Cloud"
{
    float3 xformOp:scale = (2, 2, 2)
    double3 xformOp:translate = (0, 0, 3)
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]

    def SphereLight "Glow"
    {
    }
}

def SpatialAudio "Speaker"
{
    double3 xformOp:translate = (4, 0, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def DiskLight "Led"
    {
    }
}

def GenerativeProcedural "Proc"
{
    double3 xformOp:translate = (0, -2, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def SphereLight "Spark"
    {
    }
}

def "Untyped"
{
    double3 xformOp:translate = (0, 7, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def SphereLight "Loose"
    {
    }
}

def Scope "Group"
{
    double3 xformOp:translate = (0, 9, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def SphereLight "Scoped"
    {
    }
}
"""


# The text reader's fixture (tests/data/usd/reader/): every form usd-core reads that openusd 0.8
# alone refused, on the lights' own inputs, beside a reference to a MaterialX layer and a sublayer
# that does not exist (usd-core composes without both, with a warning). Written as text by hand:
# usd-core would write it back canonically, and the point is the author's spelling.
READER_USDA = r'''#usda 1.0
(
    doc = """A layer as DCCs and OpenUSD's own test scenes write it:
    every form below is read by usd-core."""
    metersPerUnit = .01
    upAxis = "Y"
    subLayers = [
        @./missing_sublayer.usda@
    ]
)

// A comment in the C++ style, as testUsdLuxLightListAPI writes them.
def Xform "Lights" /* and a block comment */
{
    double3 xformOp:translate = (0., .5, -1.)
    uniform token[] xformOpOrder = ["xformOp:translate"]

    def SphereLight "Sphere"
    {
        config token info:id = "SphereLight"   // config: the old spelling of uniform
        float inputs:intensity = 2.
        float inputs:radius = .25
        color3f inputs:color = (1, .5, 0.)
        bool inputs:normalize = 2
        float inputs:exposure.timeSamples = {
            0: 0.,
            1.: .5,
        }
    }

    def DomeLight "Dome"
    {
        asset inputs:texture:file = "grid.png"
        float inputs:intensity = 1.e-1
    }

    def DiskLight "Off" (
        active = False
    )
    {
    }

    def RectLight "Rect" (
        prepend apiSchemas = ["ShapingAPI"]
    )
    {
        float inputs:width = 2.
        float inputs:shaping:cone:angle = 45.
        float inputs:shaping:cone:softness = .1
        float inputs:shaping:focus = -.5e-1
    }
}

def Xform "Looks" (
    prepend references = @./looks.mtlx@</MaterialX>
)
{
    def DistantLight "BesideTheLook"
    {
        float inputs:angle = 1.
    }
}
'''


def write_reader():
    d = os.path.join(DATA, "usd", "reader")
    write(os.path.join(d, "forms.usda"), READER_USDA.encode("utf-8"))
    # A MaterialX document (not USD): what usd-core without the MaterialX plugin cannot read.
    write(os.path.join(d, "looks.mtlx"), b'<?xml version="1.0"?>\n<materialx version="1.38">\n</materialx>\n')
    write(os.path.join(d, "grid.png"), png_bytes(2, 1, [255, 0, 0, 0, 0, 255]))


def write_ancestors():
    write(os.path.join(DATA, "usd", "ancestors", "ancestors.usda"), ANCESTORS_USDA.encode("ascii"))


# What luxeval reads and does not apply (tests/usd_fixtures.rs "unapplied"): light filters, link
# collections (some that restrict, some that say nothing: an explicit empty list, includeRoot
# authored true), shaping inputs with and without ShapingAPI, light lists with and without their
# API, and targets that usd-core maps through a reference (list edits folded) and into an
# instance.
UNAPPLIED_RIG_USDA = """#usda 1.0

def Xform "Rig"
{
    def LightFilter "Gobo"
    {
    }

    def SphereLight "Key"
    {
        rel light:filters = </Rig/Gobo>
        rel collection:lightLink:includes = </Rig/Prop>
    }

    def Xform "Prop"
    {
    }
}
"""

UNAPPLIED_USDA = """#usda 1.0
(
    startTimeCode = 0
    endTimeCode = 1
)

def Xform "World" (
    prepend apiSchemas = ["ListAPI"]
)
{
    rel lightList = [</World/Filtered>, </World/Linked>, </World/Rig/Key>]
    token lightList:cacheBehavior.timeSamples = {
        0: "consumeAndHalt",
        1: "consumeAndContinue",
    }

    def LightFilter "Gobo"
    {
    }

    def LightFilter "Barn"
    {
    }

    def SphereLight "Filtered"
    {
        rel light:filters = [</World/Gobo>, </World/Barn>]
    }

    def RectLight "Linked"
    {
        uniform bool collection:lightLink:includeRoot = 0
        rel collection:lightLink:includes = </World/Geo/Floor>
        rel collection:lightLink:excludes = </World/Geo/Floor/Tile>
        uniform token collection:lightLink:expansionRule = "explicitOnly"
        rel collection:shadowLink:excludes = </World/Geo/Wall>
    }

    def DiskLight "RootOff"
    {
        uniform bool collection:shadowLink:includeRoot = 0
    }

    def SphereLight "Expr"
    {
        uniform pathExpression collection:lightLink:membershipExpression = "/World/Geo/Floor//"
    }

    def SphereLight "Quiet"
    {
        uniform bool collection:lightLink:includeRoot = 1
        rel collection:lightLink:includes = None
        rel collection:shadowLink:excludes = []
        rel light:filters = []
    }

    def DiskLight "UnshapedSpot"
    {
        float inputs:intensity = 5
        float inputs:shaping:cone:angle = 30
        float inputs:shaping:cone:softness = 0.2
    }

    def DiskLight "ShapedSpot" (
        prepend apiSchemas = ["ShapingAPI"]
    )
    {
        float inputs:shaping:cone:angle = 30
        float inputs:shaping:focus = 2
    }

    def Xform "Rig" (
        prepend references = @rig.usda@</Rig>
    )
    {
        over "Key"
        {
            prepend rel light:filters = </World/Barn>
            delete rel collection:lightLink:includes = </World/Rig/Prop>
            prepend rel collection:lightLink:excludes = </World/Geo/Wall>
        }
    }

    def Xform "Inst" (
        instanceable = true
        prepend references = @rig.usda@</Rig>
    )
    {
    }

    def Scope "Geo"
    {
        def Xform "Floor"
        {
            def Xform "Tile"
            {
            }
        }

        def Xform "Wall"
        {
        }
    }
}

def Scope "Lists" (
    prepend apiSchemas = ["LightListAPI"]
)
{
    rel lightList = </World/Linked>
}

def Scope "Bare"
{
    token lightList:cacheBehavior = "ignore"
}
"""

UNAPPLIED_TIMES = [0, 1]


def write_unapplied():
    d = os.path.join(DATA, "usd", "unapplied")
    write(os.path.join(d, "unapplied.usda"), UNAPPLIED_USDA.encode("ascii"))
    write(os.path.join(d, "rig.usda"), UNAPPLIED_RIG_USDA.encode("ascii"))


def targets(rel):
    return [str(p) for p in rel.GetTargets()] if rel else []


def link_record(coll):
    """Everything usd-core composes for one of a light's link collections (UsdCollectionAPI)."""
    include_root = coll.GetIncludeRootAttr()
    expression = coll.GetMembershipExpressionAttr()
    return {
        "name": coll.GetName(),
        "include_root": bool(include_root.Get()),
        "include_root_authored": bool(include_root.HasAuthoredValue()),
        "includes": targets(coll.GetIncludesRel()),
        "includes_authored": bool(coll.GetIncludesRel().HasAuthoredTargets()),
        "excludes": targets(coll.GetExcludesRel()),
        "excludes_authored": bool(coll.GetExcludesRel().HasAuthoredTargets()),
        "expansion_rule": str(coll.GetExpansionRuleAttr().Get()),
        "membership_expression": (
            expression.Get().GetText() if expression.HasAuthoredValue() else None
        ),
    }


def dump_unapplied(scene_rel, out_name, times):
    """What usd-core composes for what luxeval reads and does not apply: every light's
    ``light:filters`` targets, both link collections, its authored ``inputs:shaping:*`` and
    whether ShapingAPI is applied; every prim's light list (ListAPI / LightListAPI applied, or
    ``lightList`` / ``lightList:cacheBehavior`` authored) at each time. Raw data: which of it
    luxeval reports is luxeval's rule, applied by the test to these records."""
    path = os.path.join(DATA, scene_rel)
    stage = Usd.Stage.Open(path)
    if stage is None:
        sys.exit(f"cannot open {path}")
    prims = list(stage.Traverse(Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)))
    lights = []
    for p in prims:
        if not is_light(p):
            continue
        light = UsdLux.LightAPI(p)
        lights.append({
            "path": str(p.GetPath()),
            "filters": targets(light.GetFiltersRel()),
            "collections": [
                link_record(light.GetLightLinkCollectionAPI()),
                link_record(light.GetShadowLinkCollectionAPI()),
            ],
            "shaping_api": bool(p.HasAPI(UsdLux.ShapingAPI)),
            "authored_shaping_inputs": [
                a.GetName() for a in p.GetAuthoredAttributes()
                if a.GetName().startswith("inputs:shaping:")
            ],
        })
    samples = []
    for t in [None] + list(times):
        tc = Usd.TimeCode.EarliestTime() if t is None else Usd.TimeCode(t)
        lists = []
        for p in prims:
            apis = [s for s in ("ListAPI", "LightListAPI") if s in p.GetAppliedSchemas()]
            rel = p.GetRelationship("lightList")
            behavior = p.GetAttribute("lightList:cacheBehavior")
            if not (apis or (rel and rel.HasAuthoredTargets()) or (behavior and behavior.HasAuthoredValue())):
                continue
            value = behavior.Get(tc) if behavior else None
            lists.append({
                "path": str(p.GetPath()),
                "api": apis[0] if apis else None,
                "targets": targets(rel),
                "cache_behavior": None if value is None else str(value),
            })
        samples.append({"time": t, "light_lists": lists})
    out = {
        "generator": "tools/gen_usd_fixtures.py",
        "usd_version": ".".join(str(x) for x in Usd.GetVersion()),
        "scene": scene_rel,
        "lights": lights,
        "samples": samples,
    }
    dst = os.path.join(DATA, "usd", "expected", out_name + ".json")
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    with open(dst, "w") as f:
        json.dump(out, f, indent=None, separators=(",", ":"))
        f.write("\n")
    print(f"{dst}: {len(lights)} lights, {len(samples[0]['light_lists'])} light lists x {len(samples)} times")


def unapplied():
    write_unapplied()
    dump("usd/unapplied/unapplied.usda", "unapplied", UNAPPLIED_TIMES)
    dump_unapplied("usd/unapplied/unapplied.usda", "unapplied_links", UNAPPLIED_TIMES)


# Mesh lights and portals (DESIGN.md §7 M1–M2, §8 P1; tests/usd_fixtures.rs "mesh"): written
# with usd-core's API, and what they must read as computed here, by usd-core and NumPy, never by
# luxeval: each mesh light's fan triangle count and world-space area (holes removed, degenerate
# triangles dropped), its emitting front (a world-space normal per triangle), its tint and the
# kind of its source; each portal's size, world matrix and the domes that name it.
MESH_TIMES = [0, 5, 10]


def write_mesh_lights():
    from pxr import Gf, UsdShade, Vt

    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    world = UsdGeom.Xform.Define(stage, "/World")

    looks = "/World/Looks"
    UsdGeom.Scope.Define(stage, looks)

    def material(name, shader_id, emissive=None, connect_emissive=False, through_graph=False):
        mat = UsdShade.Material.Define(stage, f"{looks}/{name}")
        shader = UsdShade.Shader.Define(stage, f"{looks}/{name}/Surface")
        shader.CreateIdAttr(shader_id)
        out = shader.CreateOutput("surface", Sdf.ValueTypeNames.Token)
        if emissive is not None:
            shader.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*emissive))
        if connect_emissive:
            tex = UsdShade.Shader.Define(stage, f"{looks}/{name}/Texture")
            tex.CreateIdAttr("UsdUVTexture")
            rgb = tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
            shader.CreateInput("emissiveColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(rgb)
        if through_graph:
            graph = UsdShade.NodeGraph.Define(stage, f"{looks}/{name}/Graph")
            gout = graph.CreateOutput("surface", Sdf.ValueTypeNames.Token)
            gout.ConnectToSource(out)
            mat.CreateSurfaceOutput().ConnectToSource(gout)
        else:
            mat.CreateSurfaceOutput().ConnectToSource(out)
        return mat

    glow = material("Glow", "UsdPreviewSurface", emissive=(2.0, 1.0, 0.5))
    dark = material("Dark", "UsdPreviewSurface")
    custom = material("Custom", "ND_standard_surface_surfaceshader", emissive=(1.0, 1.0, 1.0))
    connected = material("Connected", "UsdPreviewSurface", connect_emissive=True)
    graph = material("Graph", "UsdPreviewSurface", emissive=(3.0, 3.0, 3.0), through_graph=True)

    def bind(prim, mat):
        UsdShade.MaterialBindingAPI.Apply(prim).Bind(mat)

    def mesh(path, points, counts, indices, **kw):
        m = UsdGeom.Mesh.Define(stage, path)
        UsdLux.MeshLightAPI.Apply(m.GetPrim())
        if isinstance(points, dict):
            for t, pts in points.items():
                m.CreatePointsAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*p) for p in pts]), t)
        else:
            m.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(*p) for p in points]))
        m.CreateFaceVertexCountsAttr(Vt.IntArray(counts))
        m.CreateFaceVertexIndicesAttr(Vt.IntArray(indices))
        if "holes" in kw:
            m.CreateHoleIndicesAttr(Vt.IntArray(kw["holes"]))
        if "orientation" in kw:
            m.CreateOrientationAttr(kw["orientation"])
        if "double_sided" in kw:
            m.CreateDoubleSidedAttr(kw["double_sided"])
        if "scheme" in kw:
            m.CreateSubdivisionSchemeAttr(kw["scheme"])
        light = UsdLux.LightAPI(m.GetPrim())
        light.CreateIntensityAttr(kw.get("intensity", 10.0))
        if "sync" in kw:
            m.GetPrim().CreateAttribute("light:materialSyncMode", Sdf.ValueTypeNames.Token,
                                        variability=Sdf.VariabilityUniform).Set(kw["sync"])
        return m

    # An ancestor binds Glow: the meshes below without their own binding inherit it.
    signs = UsdGeom.Xform.Define(stage, "/World/Signs")
    signs.AddTranslateOp().Set(Gf.Vec3d(0.0, 2.0, -3.0))
    bind(signs.GetPrim(), glow)
    # Two quads sharing an edge, 2 × 1 each.
    mesh("/World/Signs/Quads",
         [(0, 0, 0), (2, 0, 0), (2, 1, 0), (0, 1, 0), (4, 0, 0), (4, 1, 0)],
         [4, 4], [0, 1, 2, 3, 1, 4, 5, 2], scheme="none")
    # A regular pentagon (a fan of three), leftHanded and double-sided, rotated.
    import math
    pent = [(math.cos(2 * math.pi * k / 5), math.sin(2 * math.pi * k / 5), 0.0) for k in range(5)]
    p = mesh("/World/Signs/Pentagon", pent, [5], [0, 1, 2, 3, 4],
             orientation="leftHanded", double_sided=True)
    p.AddRotateXYZOp().Set(Gf.Vec3f(30.0, 45.0, 0.0))
    # A 3 × 1 strip of unit quads with the middle one a hole, and a quad whose fan has a
    # degenerate triangle (three collinear vertices).
    mesh("/World/Signs/Holes",
         [(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0), (0, 1, 0), (1, 1, 0), (2, 1, 0), (3, 1, 0),
          (5, 0, 0), (6, 0, 0), (7, 0, 0), (6, 1, 0)],
         [4, 4, 4, 4], [0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 8, 9, 10, 11], holes=[1])
    # A mirroring, scaling, rotating transform; its own binding (Dark) wins over the ancestor's.
    mir = mesh("/World/Signs/Mirrored", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [4], [0, 1, 2, 3])
    mir.AddScaleOp().Set(Gf.Vec3f(-1.0, 2.0, 0.5))
    mir.AddRotateYOp().Set(20.0)
    bind(mir.GetPrim(), dark)
    # Time-sampled points (the quad grows from 1 × 1 to 3 × 1) and a shader that is not
    # UsdPreviewSurface.
    anim = mesh("/World/Signs/Animated",
                {0: [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)],
                 10: [(0, 0, 0), (3, 0, 0), (3, 1, 0), (0, 1, 0)]},
                [4], [0, 1, 2, 3])
    bind(anim.GetPrim(), custom)
    conn = mesh("/World/Signs/Connected", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [3], [0, 1, 2])
    bind(conn.GetPrim(), connected)
    gr = mesh("/World/Signs/Routed", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [3], [0, 1, 2])
    bind(gr.GetPrim(), graph)
    mesh("/World/Signs/Independent", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [3], [0, 1, 2],
         sync="independent")
    # No binding anywhere above.
    UsdGeom.Xform.Define(stage, "/World/Bare")
    mesh("/World/Bare/Strip", [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)], [4], [0, 1, 2, 3])

    # Portals: a dome names a portal and a prim that is not one; another portal no dome names.
    sky = UsdLux.DomeLight_1.Define(stage, "/World/Sky")
    window = UsdLux.PortalLight.Define(stage, "/World/Window")
    window.CreateWidthAttr(2.0)
    window.CreateHeightAttr(1.5)
    window.CreateIntensityAttr(2.0)
    window.CreateExposureAttr(1.0)
    window.CreateColorAttr(Gf.Vec3f(1.0, 0.5, 0.25))
    wx = UsdGeom.Xformable(window.GetPrim())
    wx.AddTranslateOp().Set(Gf.Vec3d(1.0, 2.0, 3.0))
    wx.AddRotateYOp().Set(90.0)
    skylight = UsdLux.PortalLight.Define(stage, "/World/Skylight")
    UsdGeom.Xformable(skylight.GetPrim()).AddTranslateOp().Set(Gf.Vec3d(0.0, 5.0, 0.0))
    sky.CreatePortalsRel().SetTargets([window.GetPath(), Sdf.Path("/World/Signs/Quads")])
    return stage


def mesh_expectations(stage, times):
    """Every mesh light and portal at every time, computed by usd-core and NumPy."""
    import numpy as np
    from pxr import UsdShade

    def tint_of(prim, tc):
        sync = prim.GetAttribute("light:materialSyncMode")
        mode = sync.Get() if sync and sync.HasAuthoredValue() else "materialGlowTintsLight"
        if mode != "materialGlowTintsLight":
            return [1.0, 1.0, 1.0], "mode"
        mat, _rel = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
        if not mat:
            return [1.0, 1.0, 1.0], "no_material"
        out = mat.GetSurfaceOutput()
        sources = out.GetConnectedSources()[0]
        if not sources:
            return [1.0, 1.0, 1.0], "not_evaluated"
        src = sources[0].source.GetPrim()
        if src.GetTypeName() != "Shader":
            return [1.0, 1.0, 1.0], "not_evaluated"
        shader = UsdShade.Shader(src)
        if shader.GetIdAttr().Get() != "UsdPreviewSurface":
            return [1.0, 1.0, 1.0], "not_evaluated"
        emissive = shader.GetInput("emissiveColor")
        if emissive and emissive.HasConnectedSource():
            return [1.0, 1.0, 1.0], "not_evaluated"
        v = emissive.Get(tc) if emissive else None
        return ([0.0, 0.0, 0.0] if v is None else [float(x) for x in v]), "emissive"

    samples = []
    for t in [None] + list(times):
        tc = Usd.TimeCode.EarliestTime() if t is None else Usd.TimeCode(t)
        cache = UsdGeom.XformCache(tc)
        meshes, portals = [], []
        for prim in stage.Traverse():
            m = np.array(cache.GetLocalToWorldTransform(prim), dtype=np.float64)
            if prim.HasAPI(UsdLux.MeshLightAPI):
                mesh = UsdGeom.Mesh(prim)
                pts = np.array(mesh.GetPointsAttr().Get(tc), dtype=np.float64)
                counts = list(mesh.GetFaceVertexCountsAttr().Get(tc))
                idx = list(mesh.GetFaceVertexIndicesAttr().Get(tc))
                holes = set(mesh.GetHoleIndicesAttr().Get(tc) or [])
                left = mesh.GetOrientationAttr().Get(tc) == UsdGeom.Tokens.leftHanded
                # USD row vectors: p_world = [p 1] · M.
                wp = np.hstack([pts, np.ones((len(pts), 1))]) @ m
                wp = wp[:, :3]
                tris, start = [], 0
                for face, n in enumerate(counts):
                    ids = idx[start:start + n]
                    start += n
                    if face in holes:
                        continue
                    for i in range(1, n - 1):
                        tris.append((ids[0], ids[i], ids[i + 1]))
                # The object-space front, −n for leftHanded, carried by the inverse transpose.
                normal_matrix = np.linalg.inv(m[:3, :3])  # rows: (M^-1) for row vectors
                areas, normals = [], []
                for a, b, c in tris:
                    areas.append(0.5 * np.linalg.norm(np.cross(wp[b] - wp[a], wp[c] - wp[a])))
                    n_obj = np.cross(pts[b] - pts[a], pts[c] - pts[a]) * (-1.0 if left else 1.0)
                    n_world = normal_matrix @ n_obj
                    with np.errstate(invalid="ignore"):  # a degenerate triangle, dropped below
                        normals.append(n_world / np.linalg.norm(n_world))
                largest = max(areas) if areas else 0.0
                kept = [i for i, ar in enumerate(areas) if ar > 1e-12 * largest]
                rgb, kind = tint_of(prim, tc)
                meshes.append({
                    "path": str(prim.GetPath()),
                    "triangles": len(kept),
                    "area": float(sum(areas[i] for i in kept)),
                    "normals": [[float(x) for x in normals[i]] for i in kept],
                    "tint": rgb,
                    "tint_kind": kind,
                    "double_sided": bool(mesh.GetDoubleSidedAttr().Get(tc)),
                    "subdivision_scheme": str(mesh.GetSubdivisionSchemeAttr().Get(tc)),
                })
            elif prim.IsA(UsdLux.PortalLight):
                portal = UsdLux.PortalLight(prim)
                domes = []
                for d in stage.Traverse():
                    if d.IsA(UsdLux.DomeLight_1) or d.IsA(UsdLux.DomeLight):
                        rel = d.GetRelationship("portals")
                        if rel and prim.GetPath() in rel.GetTargets():
                            domes.append(str(d.GetPath()))
                portals.append({
                    "path": str(prim.GetPath()),
                    "width": float(portal.GetWidthAttr().Get(tc)),
                    "height": float(portal.GetHeightAttr().Get(tc)),
                    "world": [[float(m[r][c]) for c in range(4)] for r in range(4)],
                    "domes": domes,
                })
        domes = []
        for d in stage.Traverse():
            if d.IsA(UsdLux.DomeLight_1) or d.IsA(UsdLux.DomeLight):
                rel = d.GetRelationship("portals")
                domes.append({
                    "path": str(d.GetPath()),
                    "portals": [str(p) for p in rel.GetTargets()] if rel else [],
                })
        samples.append({"time": t, "meshes": meshes, "portals": portals, "domes": domes})
    return samples


# Bad topology (DESIGN.md §7 M1): each a mesh light whose one attribute is wrong; the CLI
# refuses a query on it with exit 2 naming the prim and the attribute (cli/tests/bad_inputs.rs).
BAD_MESHES = {
    "count_below_3": ("faceVertexCounts", [4, 2], [0, 1, 2, 3, 0, 1], [], [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]),
    "index_out_of_range": ("faceVertexIndices", [4], [0, 1, 2, 7], [], [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]),
    "negative_index": ("faceVertexIndices", [4], [0, 1, -2, 3], [], [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]),
    "counts_not_summing": ("faceVertexIndices", [4], [0, 1, 2], [], [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]),
    "non_finite_point": ("points", [4], [0, 1, 2, 3], [], [(0, 0, 0), (1, 0, 0), (1, float("nan"), 0), (0, 1, 0)]),
    "hole_out_of_range": ("holeIndices", [4], [0, 1, 2, 3], [3], [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]),
}


def write_bad_meshes():
    from pxr import Gf, Vt
    for name, (_attr, counts, indices, holes, points) in BAD_MESHES.items():
        stage = Usd.Stage.CreateInMemory()
        m = UsdGeom.Mesh.Define(stage, "/Bad")
        UsdLux.MeshLightAPI.Apply(m.GetPrim())
        m.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(*p) for p in points]))
        m.CreateFaceVertexCountsAttr(Vt.IntArray(counts))
        m.CreateFaceVertexIndicesAttr(Vt.IntArray(indices))
        if holes:
            m.CreateHoleIndicesAttr(Vt.IntArray(holes))
        write(os.path.join(DATA, "usd", "mesh", "bad", f"{name}.usda"),
              stage.GetRootLayer().ExportToString())


def mesh_lights():
    stage = write_mesh_lights()
    path = os.path.join(DATA, "usd", "mesh", "mesh_lights.usda")
    write(path, stage.GetRootLayer().ExportToString())
    reopened = Usd.Stage.Open(path)
    out = {
        "generator": "tools/gen_usd_fixtures.py",
        "usd_version": ".".join(str(x) for x in Usd.GetVersion()),
        "scene": "usd/mesh/mesh_lights.usda",
        "samples": mesh_expectations(reopened, MESH_TIMES),
    }
    dst = os.path.join(DATA, "usd", "expected", "mesh_lights.json")
    with open(dst, "w") as f:
        json.dump(out, f, indent=None, separators=(",", ":"))
        f.write("\n")
    print(f"{dst}: {len(out['samples'][0]['meshes'])} mesh lights, "
          f"{len(out['samples'][0]['portals'])} portals x {len(out['samples'])} times")
    dump("usd/mesh/mesh_lights.usda", "mesh_lights_inputs", MESH_TIMES)
    write_bad_meshes()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--luxtest-src", default="/work/shared/data/luxtest", help="the research/data/luxtest copy")
    ap.add_argument("--only-ancestors", action="store_true",
                    help="write and dump only the ancestor-transform fixture (leaves the others as they are)")
    ap.add_argument("--only-reader", action="store_true",
                    help="write and dump only the text reader's fixture (leaves the others as they are)")
    ap.add_argument("--openusd-src", default="/work/corpus/openusd-v24.08",
                    help=f"an OpenUSD checkout (or extracted tree) at {OPENUSD_TAG}")
    ap.add_argument("--openusd-git", default="/work/.mirror/PixarAnimationStudios+OpenUSD/repo",
                    help="an OpenUSD git repository, for the files --openusd-src lacks (LICENSE.txt)")
    ap.add_argument("--only-openusd", action="store_true",
                    help="copy and dump only the OpenUSD parity corpus (leaves the others as they are)")
    ap.add_argument("--only-mesh", action="store_true",
                    help="write and dump only the mesh-light and portal fixtures (leaves the others as they are)")
    ap.add_argument("--only-unapplied", action="store_true",
                    help="write and dump only the filters / linking / light-list fixture (leaves the others as they are)")
    args = ap.parse_args()

    if args.only_reader:
        write_reader()
        dump("usd/reader/forms.usda", "reader_forms", [0, 1])
        return

    if args.only_openusd:
        copy_openusd(args.openusd_src, args.openusd_git)
        dump_openusd()
        return

    if args.only_ancestors:
        write_ancestors()
        dump("usd/ancestors/ancestors.usda", "ancestors", [0, 1, 2])
        return
    if args.only_unapplied:
        unapplied()
        return
    if args.only_mesh:
        mesh_lights()
        return

    copy_luxtest(args.luxtest_src)
    write_composition()

    exp = os.path.join(DATA, "usd", "expected")
    if os.path.isdir(exp):
        shutil.rmtree(exp)
    for rel in sorted(LUXTEST_FILES):
        if rel.startswith("usd/") and not rel.startswith("usd/shapes/"):
            name = os.path.splitext(os.path.basename(rel))[0]
            dump("luxtest/" + rel, "luxtest_" + name, None)
    for ext in ("usda", "usdc"):
        dump(f"usd/composition/root.{ext}", f"composition_root_{ext}", COMPOSITION_TIMES)
    dump("usd/composition/scene.usdz", "composition_scene_usdz", COMPOSITION_TIMES)
    dump("usd/composition/rig_packaged.usdz", "composition_rig_packaged_usdz", COMPOSITION_TIMES)
    write_ancestors()
    dump("usd/ancestors/ancestors.usda", "ancestors", [0, 1, 2])
    write_reader()
    dump("usd/reader/forms.usda", "reader_forms", [0, 1])
    copy_openusd(args.openusd_src, args.openusd_git)
    dump_openusd()
    unapplied()
    mesh_lights()


if __name__ == "__main__":
    main()
