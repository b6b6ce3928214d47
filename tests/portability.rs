//! The committed SPIR-V modules (one per entry point) through naga at the version wgpu uses (30.0.1), as wgpu
//! feeds it to every API it has: parsed with wgpu's own options, validated, and written
//! for Metal (MSL), DX12 (HLSL) and GL (GLSL ES 3.10); the lowest Metal and HLSL
//! shader-model versions that take it, which the README states; and the loop shape naga
//! mistranslates for those three (a loop whose `break if` re-reads a variable its
//! continuing block has just stored: every loop would drop its last iteration) absent.
//! GL itself runs in CI (`WGPU_BACKEND=gl`); Metal and DX12 have no machine here, so
//! this is how far they are checked.

use naga::{Block, Expression, Function, Handle, Statement};
use std::collections::HashSet;

/// Every entry point's module, parsed and validated as wgpu does.
fn modules() -> Vec<(splitsum_spirv::EntryPoint, naga::Module, naga::valid::ModuleInfo)> {
    splitsum_spirv::ENTRY_POINTS
        .iter()
        .map(|e| {
            // wgpu's own options for SPIR-V input (`wgpu::backend::wgpu_core`, create_shader_module).
            let options = naga::front::spv::Options { adjust_coordinate_space: false, strict_capabilities: true, block_ctx_dump_prefix: None };
            let module = naga::front::spv::parse_u8_slice(e.bytes(), &options).unwrap_or_else(|err| panic!("naga parses {}: {err:?}", e.name));
            let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
                .validate(&module)
                .unwrap_or_else(|err| panic!("naga validates {} with the default capabilities: {err:?}", e.name));
            assert_eq!(module.entry_points.len(), 1, "{}'s module holds its entry point alone", e.name);
            assert_eq!(module.entry_points[0].name, e.name, "the linkage names the module's entry point");
            (*e, module, info)
        })
        .collect()
}

/// Every entry point writes as MSL from Metal 1.2, not before (the bit reversal of the
/// radical inverse needs `reverse_bits`, which naga writes from 1.2; naga's default, 1.0,
/// stops there), and as HLSL from shader model 5.0 (wgpu's DX12 backend uses 5.1 with FXC,
/// 6.0 and up with DXC).
#[test]
fn the_modules_translate_for_metal_and_dx12() {
    let versions = [(1, 0), (1, 1), (1, 2), (2, 0), (2, 1), (2, 2), (2, 3), (2, 4), (3, 0)];
    let mut firsts = Vec::new();
    for (e, module, info) in modules() {
        let msl = |version: (u8, u8)| {
            let options = naga::back::msl::Options { lang_version: version, ..Default::default() };
            naga::back::msl::write_string(&module, &info, &options, &naga::back::msl::PipelineOptions::default())
        };
        let first = versions.iter().position(|&v| msl(v).is_ok()).unwrap_or_else(|| panic!("some Metal version takes {}", e.name));
        for &v in &versions[first..] {
            if let Err(err) = msl(v) {
                panic!("{}, Metal {}.{}: {err:?}", e.name, v.0, v.1);
            }
        }
        firsts.push(versions[first]);

        use naga::back::hlsl::ShaderModel;
        for m in [ShaderModel::V5_0, ShaderModel::V5_1, ShaderModel::V6_0] {
            let options = naga::back::hlsl::Options { shader_model: m, fake_missing_bindings: true, ..Default::default() };
            let mut out = String::new();
            if let Err(err) = naga::back::hlsl::Writer::new(&mut out, &options, &Default::default()).write(&module, &info, None) {
                panic!("{}, HLSL {m:?}: {err:?}", e.name);
            }
        }
    }
    let (major, minor) = firsts.iter().copied().max().expect("entry points");
    eprintln!("MSL: every entry point from Metal {major}.{minor}; HLSL: from shader model 5.0");
    assert_eq!((major, minor), (1, 2), "the README states the minimum Metal version");
}

/// Every compute kernel writes as GLSL ES 3.10, what wgpu's GL backend compiles.
#[test]
fn the_kernels_translate_for_gl() {
    for (e, module, info) in modules().into_iter().filter(|(e, ..)| e.stage == splitsum_spirv::Stage::Compute) {
        let ep = &module.entry_points[0];
        let options = naga::back::glsl::Options { version: naga::back::glsl::Version::new_gles(310), ..Default::default() };
        let pipeline = naga::back::glsl::PipelineOptions { shader_stage: naga::ShaderStage::Compute, entry_point: ep.name.clone(), multiview: None };
        let mut out = String::new();
        let mut writer = naga::back::glsl::Writer::new(&mut out, &module, &info, &options, &pipeline, naga::proc::BoundsCheckPolicies::default())
            .unwrap_or_else(|err| panic!("{}: {err:?}", e.name));
        writer.write().unwrap_or_else(|err| panic!("{}: {err:?}", e.name));
    }
}

/// The local variables `block` stores to.
fn stored(block: &Block, f: &Function, out: &mut HashSet<Handle<naga::LocalVariable>>) {
    for s in block.iter() {
        match s {
            Statement::Store { pointer, .. } => {
                if let Expression::LocalVariable(v) = f.expressions[*pointer] {
                    out.insert(v);
                }
            }
            Statement::Block(b) => stored(b, f, out),
            Statement::If { accept, reject, .. } => {
                stored(accept, f, out);
                stored(reject, f, out);
            }
            _ => {}
        }
    }
}

/// The local variables expression `e` loads, through any operands.
fn loads(e: Handle<Expression>, f: &Function, out: &mut HashSet<Handle<naga::LocalVariable>>, seen: &mut HashSet<Handle<Expression>>) {
    if !seen.insert(e) {
        return;
    }
    let mut operands = Vec::new();
    match &f.expressions[e] {
        Expression::Load { pointer } => {
            if let Expression::LocalVariable(v) = f.expressions[*pointer] {
                out.insert(v);
            }
            operands.push(*pointer);
        }
        Expression::Binary { left, right, .. } => operands.extend([*left, *right]),
        Expression::Unary { expr, .. } | Expression::As { expr, .. } => operands.push(*expr),
        Expression::AccessIndex { base, .. } => operands.push(*base),
        Expression::Access { base, index } => operands.extend([*base, *index]),
        Expression::Select { condition, accept, reject } => operands.extend([*condition, *accept, *reject]),
        Expression::Relational { argument, .. } => operands.push(*argument),
        Expression::Math { arg, arg1, arg2, arg3, .. } => operands.extend([Some(*arg), *arg1, *arg2, *arg3].into_iter().flatten()),
        Expression::Compose { components, .. } => operands.extend(components.iter().copied()),
        _ => {}
    }
    for o in operands {
        loads(o, f, out, seen);
    }
}

/// Loops in `block` whose `break if` reads a local variable their continuing block stores.
fn hazards(block: &Block, f: &Function) -> usize {
    let mut n = 0;
    for s in block.iter() {
        match s {
            Statement::Loop { body, continuing, break_if } => {
                if let Some(c) = break_if {
                    let (mut st, mut ld) = (HashSet::new(), HashSet::new());
                    stored(continuing, f, &mut st);
                    loads(*c, f, &mut ld, &mut HashSet::new());
                    n += usize::from(st.intersection(&ld).next().is_some());
                }
                n += hazards(body, f) + hazards(continuing, f);
            }
            Statement::Block(b) => n += hazards(b, f),
            Statement::If { accept, reject, .. } => n += hazards(accept, f) + hazards(reject, f),
            Statement::Switch { cases, .. } => n += cases.iter().map(|c| hazards(&c.body, f)).sum::<usize>(),
            _ => {}
        }
    }
    n
}

/// No loop of the module, as naga reads it, decides to stop on a condition re-evaluated
/// after its continuing block stored the next iteration's values (`xtask`'s
/// `latch_conditions_local` gives every latch a condition of its own; without it, 33 loops
/// were affected and on GL the BRDF table came out 15–44 % low).
#[test]
fn no_loop_stops_on_a_condition_its_continuing_block_overwrote() {
    let n: usize = modules()
        .iter()
        .map(|(_, module, _)| {
            let functions = module.functions.iter().map(|(_, f)| f).chain(module.entry_points.iter().map(|e| &e.function));
            functions.map(|f| hazards(&f.body, f)).sum::<usize>()
        })
        .sum();
    assert_eq!(n, 0, "{n} loops would drop their last iteration on GL, Metal and DX12");
}
