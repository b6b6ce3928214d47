//! The committed SPIR-V module through naga at the version wgpu uses (30.0.1), as wgpu
//! feeds it to every API it has: parsed with wgpu's own options, validated, and written
//! for Metal (MSL), DX12 (HLSL) and GL (GLSL ES 3.10); the lowest Metal and HLSL
//! shader-model versions that take it, which the README states; and the loop shape naga
//! mistranslates for those three (a loop whose `break if` re-reads a variable its
//! continuing block has just stored: every loop would drop its last iteration) absent.
//! GL itself runs in CI (`WGPU_BACKEND=gl`); Metal and DX12 have no machine here, so
//! this is how far they are checked.

use naga::{Block, Expression, Function, Handle, Statement};
use std::collections::HashSet;

fn module() -> (naga::Module, naga::valid::ModuleInfo) {
    // wgpu's own options for SPIR-V input (`wgpu::backend::wgpu_core`, create_shader_module).
    let options = naga::front::spv::Options { adjust_coordinate_space: false, strict_capabilities: true, block_ctx_dump_prefix: None };
    let module = naga::front::spv::parse_u8_slice(bytemuck::cast_slice(splitsum_spirv::words()), &options).expect("naga parses the module");
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
        .validate(&module)
        .unwrap_or_else(|e| panic!("naga validates the module with the default capabilities: {e:?}"));
    (module, info)
}

/// Every entry point of the module writes as MSL from Metal 1.2, not before (the bit
/// reversal of the radical inverse needs `reverse_bits`, which naga writes from 1.2; naga's
/// default, 1.0, stops there), and as HLSL from shader model 5.0 (wgpu's DX12 backend uses
/// 5.1 with FXC, 6.0 and up with DXC).
#[test]
fn the_module_translates_for_metal_and_dx12() {
    let (module, info) = module();
    let msl = |version: (u8, u8)| {
        let options = naga::back::msl::Options { lang_version: version, ..Default::default() };
        naga::back::msl::write_string(&module, &info, &options, &naga::back::msl::PipelineOptions::default())
    };
    let versions = [(1, 0), (1, 1), (1, 2), (2, 0), (2, 1), (2, 2), (2, 3), (2, 4), (3, 0)];
    let first = versions.iter().position(|&v| msl(v).is_ok()).expect("some Metal version takes the module");
    for &v in &versions[first..] {
        if let Err(e) = msl(v) {
            panic!("Metal {}.{}: {e:?}", v.0, v.1);
        }
    }
    let (major, minor) = versions[first];
    eprintln!("MSL: every entry point from Metal {major}.{minor}; before it: {:?}", msl(versions[first.saturating_sub(1)]).err());
    assert_eq!((major, minor), (1, 2), "the README states the minimum Metal version");

    use naga::back::hlsl::ShaderModel;
    let hlsl = |model: ShaderModel| {
        let options = naga::back::hlsl::Options { shader_model: model, fake_missing_bindings: true, ..Default::default() };
        let mut out = String::new();
        naga::back::hlsl::Writer::new(&mut out, &options, &Default::default()).write(&module, &info, None).map(|_| out.len())
    };
    let models = [ShaderModel::V5_0, ShaderModel::V5_1, ShaderModel::V6_0];
    for m in models {
        if let Err(e) = hlsl(m) {
            panic!("HLSL {m:?}: {e:?}");
        }
    }
    eprintln!("HLSL: every entry point from shader model 5.0");
}

/// Every compute kernel writes as GLSL ES 3.10, what wgpu's GL backend compiles.
#[test]
fn the_kernels_translate_for_gl() {
    let (module, info) = module();
    for ep in module.entry_points.iter().filter(|e| e.stage == naga::ShaderStage::Compute) {
        let options = naga::back::glsl::Options { version: naga::back::glsl::Version::new_gles(310), ..Default::default() };
        let pipeline = naga::back::glsl::PipelineOptions { shader_stage: naga::ShaderStage::Compute, entry_point: ep.name.clone(), multiview: None };
        let mut out = String::new();
        let mut writer = naga::back::glsl::Writer::new(&mut out, &module, &info, &options, &pipeline, naga::proc::BoundsCheckPolicies::default())
            .unwrap_or_else(|e| panic!("{}: {e:?}", ep.name));
        writer.write().unwrap_or_else(|e| panic!("{}: {e:?}", ep.name));
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
    let (module, _) = module();
    let functions = module.functions.iter().map(|(_, f)| f).chain(module.entry_points.iter().map(|e| &e.function));
    let n: usize = functions.map(|f| hazards(&f.body, f)).sum();
    assert_eq!(n, 0, "{n} loops would drop their last iteration on GL, Metal and DX12");
}
