//! The flags that choose the continuous model a frame renders and is measured against:
//! `--classification`, `--absorption`, `--reconstruction`, and `--slab-post`'s default.

/// `--reconstruction`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReconstructionArg {
    Kernel,
    Trilinear,
}

impl From<ReconstructionArg> for crate::reference::continuous::Reconstruction {
    fn from(a: ReconstructionArg) -> Self {
        match a {
            ReconstructionArg::Kernel => Self::Kernel,
            ReconstructionArg::Trilinear => Self::Trilinear,
        }
    }
}

/// `--slab-post`'s default for `shading` and `reconstruction`, voxel spacings: the step that keeps
/// the midpoint rule's error against the post-classified integral under the 44 dB target with a
/// margin (docs/post-classification.md): with the kernel, 0.7 for emission, 0.4 where gradients
/// light the samples (the lit colour varies faster along a ray than the value does); trilinear
/// values have kinks at every voxel plane, which the midpoint rule converges on more slowly: 0.5
/// and 0.3 (measured on the real-size CT phantom and the shared volumes at 512²).
pub fn default_post_slab(shading: &str, reconstruction: ReconstructionArg) -> f32 {
    match (shading == "emission", reconstruction) {
        (true, ReconstructionArg::Kernel) => 0.7,
        (false, ReconstructionArg::Kernel) => 0.4,
        (true, ReconstructionArg::Trilinear) => 0.5,
        (false, ReconstructionArg::Trilinear) => 0.3,
    }
}

/// `--classification`: shade the samples, then reconstruct (the paper's `pre`), or reconstruct
/// the values, then classify (`post`; `footprint::render::post`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ClassificationArg {
    #[default]
    Pre,
    Post,
}

impl ClassificationArg {
    /// The name the flag and the JSON use.
    pub fn name(self) -> &'static str {
        match self {
            ClassificationArg::Pre => "pre",
            ClassificationArg::Post => "post",
        }
    }
}

/// `--blend`: how a ray's samples become a pixel (`footprint::render::post`'s `blend`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BlendArg {
    #[default]
    Composite,
    Mip,
    Minip,
    Average,
}

impl From<BlendArg> for footprint::render::Blend {
    fn from(b: BlendArg) -> Self {
        use footprint::render::Blend;
        match b {
            BlendArg::Composite => Blend::Composite,
            BlendArg::Mip => Blend::Maximum,
            BlendArg::Minip => Blend::Minimum,
            BlendArg::Average => Blend::Average,
        }
    }
}

/// `--absorption`: the continuous model both slicings render and the continuous reference
/// integrates (`footprint::render::absorption`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum AbsorptionArg {
    Opacity,
    Extinction,
}

impl From<AbsorptionArg> for footprint::render::Absorption {
    fn from(a: AbsorptionArg) -> Self {
        match a {
            AbsorptionArg::Extinction => Self::Extinction,
            AbsorptionArg::Opacity => Self::Opacity,
        }
    }
}

/// `--endian`: the byte order of a raw volume's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EndianArg {
    /// Least significant byte first (x86, ARM).
    Little,
    /// Most significant byte first (network order; many older CT files).
    Big,
}
