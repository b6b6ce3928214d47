//! `xtask spirv [--check]`: compiles `shaders/` to SPIR-V with rust-gpu and writes one
//! module per entry point, `spirv/src/modules/NAME.spv`, and `spirv/src/linkage.rs`, the
//! entry points' names, stages, workgroup sizes and bindings reflected from the modules
//! themselves. `--check` compiles and compares instead, failing if any committed file
//! differs or is left over.
//!
//! This is the only place rust-gpu runs: the workspace builds on stable from the committed
//! files (renderling's pattern: committed SPIR-V with generated linkage, regenerated and
//! diffed by CI).

use rspirv::dr::{Instruction, Module, Operand};
use rspirv::spirv::{Decoration, Dim, ExecutionMode, ExecutionModel, Op, StorageClass};
use spirv_builder::{ModuleResult, ShaderPanicStrategy, SpirvBuilder};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

type Error = Box<dyn std::error::Error>;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let check = match args.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
        ["spirv"] => false,
        ["spirv", "--check"] => true,
        _ => {
            eprintln!("usage: xtask spirv [--check]");
            return ExitCode::from(2);
        }
    };
    match run(check) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("xtask lives in the repository").to_path_buf()
}

fn run(check: bool) -> Result<bool, Error> {
    let root = root();
    let mut builder = SpirvBuilder::new(root.join("shaders"), "spirv-unknown-vulkan1.1");
    builder.shader_panic_strategy = ShaderPanicStrategy::SilentExit;
    builder.release = true;
    // One module per entry point, each holding only what its entry point calls (rust-gpu
    // splits the linked module and removes the dead code of each part): a pipeline
    // compiles only its own code. One module with every entry point took a browser's GPU
    // process past 11 GB compiling one kernel (issue 33).
    builder.multimodule = true;
    // The workspace pins stable; the shader crate must build with the nightly this xtask
    // runs on (xtask/rust-toolchain.toml), so say so explicitly to the nested cargo.
    builder.toolchain_overwrite = std::env::var("RUSTUP_TOOLCHAIN").ok();
    let result = builder.build()?;
    let ModuleResult::MultiModule(parts) = &result.module else { return Err("rust-gpu returned one module where one per entry point was asked".into()) };
    let (mut rewritten, mut renamed) = (0, 0);
    let mut entries = BTreeMap::new();
    let mut outputs = Vec::new();
    for path in parts.values() {
        let spv = std::fs::read(path)?;
        let words: Vec<u32> = spv.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        let mut module = rspirv::dr::load_words(&words).map_err(|e| format!("reading {} back: {e}", path.display()))?;
        rewritten += latch_conditions_local(&mut module);
        renamed += wgsl_entry_names(&mut module)?;
        let spv: Vec<u8> = {
            use rspirv::binary::Assemble;
            module.assemble().iter().flat_map(|w| w.to_le_bytes()).collect()
        };
        let found = entry_points(&module)?;
        let name = match found.keys().collect::<Vec<_>>()[..] {
            [name] => name.clone(),
            _ => return Err(format!("{} holds {} entry points, not one", path.display(), found.len()).into()),
        };
        outputs.push((root.join(MODULES).join(format!("{name}.spv")), spv));
        entries.extend(found);
    }
    eprintln!("xtask: {rewritten} loop latches given a condition of their own (see latch_conditions_local)");
    eprintln!("xtask: {renamed} entry points named as WGSL identifiers (see wgsl_entry_names)");
    eprintln!("xtask: {} modules, one per entry point", outputs.len());
    outputs.push((root.join("spirv/src/linkage.rs"), linkage(&entries).into_bytes()));

    let mut same = true;
    // A module left from an entry point that is gone.
    let wanted: BTreeSet<&PathBuf> = outputs.iter().map(|(p, _)| p).collect();
    for stale in std::fs::read_dir(root.join(MODULES)).into_iter().flatten().flatten().map(|e| e.path()) {
        if !wanted.contains(&stale) {
            let shown = stale.strip_prefix(&root).unwrap_or(&stale).display().to_string();
            if check {
                eprintln!("xtask: {shown} is no entry point's module; run `bash scripts/dev.sh spirv` and commit its removal");
                same = false;
            } else {
                std::fs::remove_file(&stale)?;
                eprintln!("xtask: removed {shown}");
            }
        }
    }
    if !check {
        std::fs::create_dir_all(root.join(MODULES))?;
    }
    for (path, bytes) in &outputs {
        let shown = path.strip_prefix(&root).unwrap_or(path).display();
        if check {
            if std::fs::read(path).ok().as_deref() != Some(bytes.as_slice()) {
                eprintln!("xtask: {shown} differs from what shaders/ compiles to; run `bash scripts/dev.sh spirv` and commit it");
                same = false;
            }
        } else if std::fs::read(path).ok().as_deref() != Some(bytes.as_slice()) {
            std::fs::write(path, bytes)?;
            eprintln!("xtask: wrote {shown}");
        }
    }
    if check && same {
        eprintln!("xtask: the {} files under spirv/src are up to date", outputs.len());
    }
    Ok(same)
}

/// Where the modules go, one per entry point, named as the entry point.
const MODULES: &str = "spirv/src/modules";

/// Gives every loop whose latch (continue block) branches on a condition computed
/// elsewhere in the loop a copy of that condition of its own: `%c2 = OpPhi %bool %c %pred…`
/// at the top of the continue block, branched on instead of `%c`.
///
/// rust-gpu's structurizer ends every loop in a continue block `OpBranchConditional %c
/// %header %merge`, where `%c` is the loop condition computed in the header. naga (wgpu
/// 30) translates such a loop for GLSL, HLSL and MSL as `while (true) { if (!init) {
/// continuing; if (!c) break; } body }` and, `%c` being out of scope there, re-evaluates it
/// from the header's phi variables *after* the continuing block has already stored the next
/// iteration's values into them: every loop then stops one iteration early and drops its
/// last term (on GL, the BRDF table came out 15–44 % low, the specular cube 34 %). SPIR-V
/// for Vulkan is regenerated from SSA and is not affected. A phi in the continue block
/// becomes a local variable of its own in naga, stored where the body ends and read in
/// the continuing block, so the condition of this iteration is what decides. Returns how
/// many loops were rewritten; `tests/portability.rs` checks naga's IR of the module for
/// the pattern.
fn latch_conditions_local(module: &mut Module) -> usize {
    use rspirv::dr::Instruction;
    let mut next_id = module.header.as_ref().map_or(1, |h| h.bound);
    let bool_type = module.types_global_values.iter().find(|i| i.class.opcode == Op::TypeBool).and_then(|i| i.result_id);
    let Some(bool_type) = bool_type else { return 0 };
    let mut rewritten = 0;
    for f in &mut module.functions {
        let label = |b: &rspirv::dr::Block| b.label.as_ref().and_then(|l| l.result_id);
        // Each loop header's (merge, continue).
        let loops: Vec<(u32, u32, u32)> = f
            .blocks
            .iter()
            .filter_map(|b| {
                let m = b.instructions.iter().find(|i| i.class.opcode == Op::LoopMerge)?;
                match (m.operands.first(), m.operands.get(1)) {
                    (Some(Operand::IdRef(merge)), Some(Operand::IdRef(cont))) => Some((label(b)?, *merge, *cont)),
                    _ => None,
                }
            })
            .collect();
        for (header, merge, cont) in loops {
            let Some(ci) = f.blocks.iter().position(|b| label(b) == Some(cont)) else { continue };
            let defined_here: BTreeSet<u32> = f.blocks[ci].instructions.iter().filter_map(|i| i.result_id).collect();
            let Some(term) = f.blocks[ci].instructions.last() else { continue };
            let (cond, a, b) = match (term.class.opcode, term.operands.as_slice()) {
                (Op::BranchConditional, [Operand::IdRef(c), Operand::IdRef(a), Operand::IdRef(b), ..]) => (*c, *a, *b),
                _ => continue,
            };
            let latch = (a == header && b == merge) || (a == merge && b == header);
            if !latch || defined_here.contains(&cond) {
                continue;
            }
            // The continue block's predecessors: blocks whose terminator names it.
            let preds: Vec<u32> = f
                .blocks
                .iter()
                .filter(|blk| blk.instructions.last().is_some_and(|t| t.operands.iter().any(|o| *o == Operand::IdRef(cont))))
                .filter_map(label)
                .collect();
            if preds.is_empty() {
                continue;
            }
            let id = next_id;
            next_id += 1;
            let operands = preds.iter().flat_map(|p| [Operand::IdRef(cond), Operand::IdRef(*p)]).collect();
            let phi = Instruction::new(Op::Phi, Some(bool_type), Some(id), operands);
            let block = &mut f.blocks[ci];
            let at = block.instructions.iter().take_while(|i| i.class.opcode == Op::Phi).count();
            block.instructions.insert(at, phi);
            let term = block.instructions.last_mut().expect("a terminator");
            term.operands[0] = Operand::IdRef(id);
            rewritten += 1;
        }
    }
    if let Some(h) = module.header.as_mut() {
        h.bound = next_id;
    }
    rewritten
}

/// Names every entry point `module_function` instead of rust-gpu's `module::function`: in a
/// browser wgpu hands the module to WebGPU as WGSL (naga's translation), where `::` is no
/// identifier and naga renames the entry points, so a pipeline asking for
/// `kernels::brdf_lut` finds none ("Entry point "kernels::brdf_lut" doesn't exist in the
/// shader module"). Returns how many were renamed.
///
/// The debug name (`OpName`) of each entry point's function is dropped (naga would name
/// that function too, and may rename the entry point to keep the names apart), and an entry
/// name may not end in a digit: naga appends `_` to such a name (`kernels_irradiance_sh9`
/// became `kernels_irradiance_sh9_`; Chromium: "Entry point "kernels_irradiance_sh9"
/// doesn't exist in the shader module", and the device was lost with it).
fn wgsl_entry_names(module: &mut Module) -> Result<usize, Error> {
    let mut renamed = 0;
    let mut functions = BTreeSet::new();
    for e in &mut module.entry_points {
        if let Some(Operand::IdRef(f)) = e.operands.get(1) {
            functions.insert(*f);
        }
        for o in &mut e.operands {
            if let Operand::LiteralString(name) = o
                && name.contains("::")
            {
                *name = name.replace("::", "_");
                renamed += 1;
            }
        }
    }
    module.debug_names.retain(|i| !(i.class.opcode == Op::Name && matches!(i.operands.first(), Some(Operand::IdRef(t)) if functions.contains(t))));
    for e in &module.entry_points {
        if let Some(Operand::LiteralString(name)) = e.operands.get(2)
            && name.ends_with(|c: char| c.is_ascii_digit())
        {
            return Err(format!("entry point {name} ends in a digit, which naga renames for WGSL (browsers): rename the function").into());
        }
    }
    Ok(renamed)
}

/// What a binding holds, as `splitsum_spirv::Resource` spells it.
fn resource(module: &Module, var: &Instruction, written: bool) -> Result<String, Error> {
    let types: HashMap<u32, &Instruction> = module.types_global_values.iter().filter_map(|i| i.result_id.map(|id| (id, i))).collect();
    let class = match var.operands.first() {
        Some(Operand::StorageClass(c)) => *c,
        _ => return Err("a variable without a storage class".into()),
    };
    let pointee = |ty: u32| -> Option<&Instruction> {
        let ptr = types.get(&ty)?;
        match ptr.operands.get(1) {
            Some(Operand::IdRef(t)) => types.get(t).copied(),
            _ => None,
        }
    };
    Ok(match class {
        StorageClass::Uniform => "Resource::Uniform".into(),
        StorageClass::StorageBuffer => format!("Resource::Storage {{ read_only: {} }}", !written),
        StorageClass::UniformConstant => {
            let mut ty = pointee(var.result_type.ok_or("untyped variable")?).ok_or("unknown variable type")?;
            if ty.class.opcode == Op::TypeSampledImage {
                match ty.operands.first() {
                    Some(Operand::IdRef(t)) => ty = types[t],
                    _ => return Err("a sampled image without an image type".into()),
                }
            }
            match ty.class.opcode {
                Op::TypeSampler => "Resource::Sampler".into(),
                Op::TypeImage => {
                    let dim = match ty.operands.get(1) {
                        Some(Operand::Dim(Dim::Dim2D)) => "D2",
                        Some(Operand::Dim(Dim::DimCube)) => "Cube",
                        Some(Operand::Dim(Dim::Dim3D)) => "D3",
                        Some(Operand::Dim(Dim::Dim1D)) => "D1",
                        d => return Err(format!("an image of dimension {d:?}").into()),
                    };
                    let arrayed = matches!(ty.operands.get(3), Some(Operand::LiteralBit32(1)));
                    let dim = if arrayed { format!("{dim}Array") } else { dim.to_string() };
                    format!("Resource::Texture {{ dimension: Dimension::{dim} }}")
                }
                op => return Err(format!("a UniformConstant binding of type {op:?}").into()),
            }
        }
        c => return Err(format!("a descriptor in storage class {c:?}").into()),
    })
}

/// The ids each function refers to, and the functions it calls.
fn function_uses(module: &Module) -> HashMap<u32, (BTreeSet<u32>, BTreeSet<u32>)> {
    let mut uses = HashMap::new();
    for f in &module.functions {
        let Some(id) = f.def.as_ref().and_then(|d| d.result_id) else { continue };
        let (mut refs, mut calls) = (BTreeSet::new(), BTreeSet::new());
        for i in f.blocks.iter().flat_map(|b| &b.instructions) {
            for o in &i.operands {
                if let Operand::IdRef(r) = o {
                    refs.insert(*r);
                }
            }
            if i.class.opcode == Op::FunctionCall
                && let Some(Operand::IdRef(callee)) = i.operands.first()
            {
                calls.insert(*callee);
            }
        }
        uses.insert(id, (refs, calls));
    }
    uses
}

/// The global variables some store or atomic writes through, following access chains.
fn written_variables(module: &Module) -> BTreeSet<u32> {
    let mut root: HashMap<u32, u32> = HashMap::new();
    for v in module.types_global_values.iter().filter(|i| i.class.opcode == Op::Variable) {
        if let Some(id) = v.result_id {
            root.insert(id, id);
        }
    }
    let mut written = BTreeSet::new();
    // Access chains may appear before the stores that use them; two passes settle them.
    for _ in 0..2 {
        for i in module.functions.iter().flat_map(|f| &f.blocks).flat_map(|b| &b.instructions) {
            let first = match i.operands.first() {
                Some(Operand::IdRef(r)) => Some(*r),
                _ => None,
            };
            match i.class.opcode {
                Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain | Op::InBoundsPtrAccessChain | Op::CopyObject | Op::Bitcast => {
                    if let (Some(base), Some(id)) = (first.and_then(|b| root.get(&b).copied()), i.result_id) {
                        root.insert(id, base);
                    }
                }
                Op::Store | Op::CopyMemory | Op::AtomicStore | Op::AtomicExchange | Op::AtomicIAdd | Op::AtomicISub | Op::AtomicOr | Op::AtomicAnd => {
                    // The pointer written through is the first operand of each of these.
                    if let Some(r) = first.and_then(|t| root.get(&t)) {
                        written.insert(*r);
                    }
                }
                _ => {}
            }
        }
    }
    written
}

/// An entry point's stage, workgroup size and bindings (`splitsum_spirv::Resource` spelled
/// out, by group and binding).
type Entry = (&'static str, [u32; 3], BTreeMap<(u32, u32), String>);

/// Every entry point of `module` with its stage, workgroup size and the bindings its call
/// tree uses.
fn entry_points(module: &Module) -> Result<BTreeMap<String, Entry>, Error> {
    let mut decorations: HashMap<u32, (Option<u32>, Option<u32>)> = HashMap::new();
    for a in module.annotations.iter().filter(|a| a.class.opcode == Op::Decorate) {
        let (Some(Operand::IdRef(target)), Some(Operand::Decoration(d))) = (a.operands.first(), a.operands.get(1)) else { continue };
        let value = match a.operands.get(2) {
            Some(Operand::LiteralBit32(v)) => *v,
            _ => continue,
        };
        let entry = decorations.entry(*target).or_default();
        match d {
            Decoration::DescriptorSet => entry.0 = Some(value),
            Decoration::Binding => entry.1 = Some(value),
            _ => {}
        }
    }
    let variables: HashMap<u32, &Instruction> = module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::Variable)
        .filter_map(|i| i.result_id.map(|id| (id, i)))
        .collect();
    let mut local_size: HashMap<u32, [u32; 3]> = HashMap::new();
    for m in &module.execution_modes {
        if let (Some(Operand::IdRef(f)), Some(Operand::ExecutionMode(ExecutionMode::LocalSize))) = (m.operands.first(), m.operands.get(1)) {
            let lit = |k: usize| match m.operands.get(k) {
                Some(Operand::LiteralBit32(v)) => *v,
                _ => 1,
            };
            local_size.insert(*f, [lit(2), lit(3), lit(4)]);
        }
    }
    let uses = function_uses(module);
    let written = written_variables(module);

    let mut entries = BTreeMap::new();
    for e in &module.entry_points {
        let (Some(Operand::ExecutionModel(model)), Some(Operand::IdRef(f)), Some(Operand::LiteralString(name))) =
            (e.operands.first(), e.operands.get(1), e.operands.get(2))
        else {
            return Err("a malformed OpEntryPoint".into());
        };
        let stage = match model {
            ExecutionModel::GLCompute => "Compute",
            ExecutionModel::Vertex => "Vertex",
            ExecutionModel::Fragment => "Fragment",
            m => return Err(format!("entry point {name} has execution model {m:?}").into()),
        };
        // Every id the entry point's call tree refers to, so that each entry point lists
        // only the bindings it uses.
        let (mut seen, mut todo, mut refs) = (BTreeSet::new(), vec![*f], BTreeSet::new());
        while let Some(g) = todo.pop() {
            if !seen.insert(g) {
                continue;
            }
            if let Some((r, c)) = uses.get(&g) {
                refs.extend(r.iter().copied());
                todo.extend(c.iter().copied());
            }
        }
        let mut bindings = BTreeMap::new();
        for r in refs {
            let (Some(var), Some((Some(group), Some(binding)))) = (variables.get(&r), decorations.get(&r)) else { continue };
            bindings.insert((*group, *binding), resource(module, var, written.contains(&r))?);
        }
        entries.insert(name.clone(), (stage, local_size.get(f).copied().unwrap_or([1, 1, 1]), bindings));
    }
    Ok(entries)
}

/// `spirv/src/linkage.rs`: every entry point with its stage, workgroup size, the bindings
/// its call tree uses and its module.
fn linkage(entries: &BTreeMap<String, Entry>) -> String {
    let mut out = String::from(
        "// @generated by `bash scripts/dev.sh spirv` (xtask/src/main.rs), reflected from the\n\
         // modules in modules/, one per entry point. Do not edit: change shaders/ and regenerate.\n\n\
         use crate::{Binding, Dimension, EntryPoint, Module, Resource, Stage};\n",
    );
    let (mut compute, mut all) = (Vec::new(), Vec::new());
    for (name, (stage, size, bindings)) in entries {
        let ident = name.replace("::", "_").to_uppercase();
        let _ = write!(out, "\n/// `{name}`.\npub const {ident}: EntryPoint = EntryPoint {{\n    name: \"{name}\",\n    stage: Stage::{stage},\n    workgroup_size: {size:?},\n    bindings: &[\n");
        for ((group, binding), resource) in bindings {
            let _ = writeln!(out, "        Binding {{ group: {group}, binding: {binding}, resource: {resource} }},");
        }
        let file = format!("modules/{name}.spv");
        let _ = write!(
            out,
            "    ],\n    module: &{ident}_MODULE,\n}};\nstatic {ident}_MODULE: Module<[u8; include_bytes!(\"{file}\").len()]> = Module(*include_bytes!(\"{file}\"));\n"
        );
        if *stage == "Compute" {
            compute.push(ident.clone());
        }
        all.push(ident);
    }
    let _ = write!(out, "\n/// Every compute entry point.\npub const KERNELS: [EntryPoint; {}] = [{}];\n", compute.len(), compute.join(", "));
    let _ = write!(out, "\n/// Every entry point.\npub const ENTRY_POINTS: [EntryPoint; {}] = [{}];\n", all.len(), all.join(", "));
    if out.contains("Dimension::") { out } else { out.replace("Binding, Dimension, EntryPoint", "Binding, EntryPoint") }
}
